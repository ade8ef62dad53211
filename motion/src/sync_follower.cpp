#include "cncd/motion/sync_follower.hpp"

#include <algorithm>
#include <cmath>

#include "profile.hpp"

namespace cncd::motion {
namespace {

// Revolutions from the end of a tap's way down (or back) at which the spindle is told to stop:
// the braking curve reaches it at a crawl, so it comes to rest within a fraction of this.
constexpr double kEndRev = 2e-4;
// A spindle slower than this (rev/s) for kRestPeriods periods in a row is at rest: an encoder
// that does not count for that long, a simulated spindle that has stopped.
constexpr double kRestRps = 0.02;
constexpr int kRestPeriods = 5;
// How far past either end of a tap the spindle may turn before the tap is stopped (rev).
constexpr double kOverrunRev = 0.25;
// The tap brakes on this share of its ramp: the spindle, which follows the command within
// its own acceleration, keeps up with the command's changes.
constexpr double kBrakeShare = 0.8;
// The ramp is this share of what the spindle can do, and of half what the axis can: following
// the spindle one period ahead, the axis's acceleration over a period may reach twice the
// ramp's where the ramp begins or ends.
constexpr double kRampShare = 0.9;
constexpr double kAxisShare = 0.5;
// A tap's axis may move at most this share of the line's speed limit in a period, plus this
// many revolutions (an encoder's counts, rounding): a larger step is a spindle position that
// jumped.
constexpr double kJumpShare = 1.25;
constexpr double kJumpSlackRev = 0.002;
// A thread settles on its helix with this time constant, in servo periods.
constexpr double kSettlePeriods = 8;

// The speed from which a ramp of `accel`, in steps of `dt`, stops within `distance`.
double braking_speed(double distance, double accel, double dt) {
  if (!(distance > 0)) return 0.0;
  const double half_step = 0.5 * accel * dt;
  return std::sqrt(2.0 * accel * distance + half_step * half_step) - half_step;
}

double toward(double from, double to, double step) {
  return from < to ? std::min(to, from + step) : std::max(to, from - step);
}

}  // namespace

void SyncFollower::start(const Segment& segment, const Spindle& spindle, bool continues) noexcept {
  const int last_direction = direction_;
  const bool chained = continues && has_helix_end_;
  has_helix_end_ = false;
  status_ = {};
  std::fill(std::begin(sent_), std::end(sent_), 0.0);
  sent_head_ = 0;
  out_at_top_ = false;
  status_.mode = segment.spindle_sync;
  status_.per_rev = segment.per_rev;
  stalled_s_ = 0;
  stopping_s_ = 0;
  rest_periods_ = 0;
  locked_ = false;
  last_s_ = 0;
  path_v_ = 0;
  path_s_ = 0;
  direction_ = spindle.direction != 0 ? spindle.direction : (spindle.rps < 0 ? -1 : 1);
  if (segment.spindle_sync == SpindleSync::tap) {
    const double axis_accel = kAxisShare * segment.max_acceleration / segment.per_rev;
    accel_ = kRampShare * std::min(spindle.acceleration, axis_accel);
    // The tap takes the spindle from the speed it turns at now, down to rest.
    command_ = std::max(0.0, direction_ * spindle.rps);
    status_.phase = SyncStatus::Phase::spindle_stopping;
    origin_ = spindle.revolutions;
    last_progress_ = 0;
  } else if (chained && direction_ == last_direction) {
    // On along the helix, from where it left the previous move: at once if the spindle is less
    // than a revolution past that point, else at the next revolution in its phase.
    const double past = direction_ * (spindle.revolutions - helix_end_);
    origin_ = helix_end_ + direction_ * (past <= 1.0 ? 0.0 : std::ceil(past));
    status_.phase = SyncStatus::Phase::index;
  } else {
    // The next whole revolution in the direction of turning: threads cut again start in phase.
    origin_ = direction_ > 0 ? std::ceil(spindle.revolutions) : std::floor(spindle.revolutions);
    status_.phase = SyncStatus::Phase::index;
  }
}

double SyncFollower::still_to_turn(int periods, double dt) const noexcept {
  const int n = std::clamp(periods, 0, kMaxDelayPeriods);
  double sum = 0;
  for (int i = 1; i <= n; ++i)
    sum += sent_[(sent_head_ - i + kMaxDelayPeriods) % kMaxDelayPeriods];
  return sum * dt;
}

void SyncFollower::watch_stall(bool stalled, const Spindle& spindle, double dt,
                               Step& out) noexcept {
  if (!stalled) {
    stalled_s_ = 0;
    return;
  }
  stalled_s_ += dt;
  if (spindle.stall_timeout_s > 0 && stalled_s_ >= spindle.stall_timeout_s) {
    out.error = RtEvent::Code::sync_stalled;
    out.error_limit = spindle.stall_timeout_s;
  }
}

SyncFollower::Step SyncFollower::step(const Segment& segment, const Spindle& spindle,
                                      double feed_override, bool stop, double dt) noexcept {
  return segment.spindle_sync == SpindleSync::tap
             ? tap_step(segment, spindle, feed_override, stop, dt)
             : thread_step(segment, spindle, stop, dt);
}

SyncFollower::Step SyncFollower::tap_step(const Segment& segment, const Spindle& spindle,
                                          double feed_override, bool stop, double dt) noexcept {
  using Phase = SyncStatus::Phase;
  Step out;
  out.drives_spindle = true;
  const double per_rev = segment.per_rev;
  const double bottom = segment.length / per_rev;  // revolutions from the top to the bottom
  // Where the spindle is now, and (below) where it will be at the end of this period: the
  // axis is told to be there then.
  const double now = direction_ * (spindle.revolutions - origin_);
  // Where the spindle will be once the command of this period reaches it: a spindle whose
  // commands come late (a field bus) still turns on those already sent. The tap brakes and
  // turns on that position, so such a spindle still comes to rest at the ends.
  const double coming = now + still_to_turn(spindle.command_delay_periods, dt);
  rest_periods_ = std::abs(spindle.rps) <= kRestRps ? rest_periods_ + 1 : 0;
  const bool at_rest = rest_periods_ >= kRestPeriods;
  if (stop && status_.phase != Phase::stopping) status_.phase = Phase::stopping;

  double target = 0;  // spindle speed wanted, rev/s, > 0 into the hole
  const double fo = std::isfinite(feed_override) ? std::max(0.0, feed_override) : 0.0;
  const double cap = std::min(spindle.max_rps, segment.axis_velocity / per_rev);
  const double brake = kBrakeShare * accel_;
  switch (status_.phase) {
    case Phase::spindle_stopping:
      target = 0;
      stopping_s_ += dt;
      if (spindle.stall_timeout_s > 0 && stopping_s_ >= spindle.stall_timeout_s &&
          std::abs(spindle.rps) > kRestRps) {
        out.error = RtEvent::Code::sync_not_at_rest;
        out.error_value = std::abs(spindle.rps) * 60.0;
        out.error_limit = spindle.stall_timeout_s;
        return out;
      }
      if (command_ == 0 && at_rest) {
        origin_ = spindle.revolutions;
        status_.phase = Phase::tapping_in;
        last_progress_ = 0;
        locked_ = true;
        // At rest, whatever was sent has been done.
        std::fill(std::begin(sent_), std::end(sent_), 0.0);
      }
      break;
    case Phase::tapping_in: {
      const double left = bottom - coming;
      if (left <= kEndRev) {
        status_.phase = Phase::tapping_out;
        target = 0;
      } else {
        target = std::min({spindle.programmed_rps * fo, cap, braking_speed(left, brake, dt)});
      }
      break;
    }
    case Phase::tapping_out: {
      // Once told to stop at the top, it stops: a position that settles a little short (a
      // field bus's estimate) does not start the spindle again.
      if (out_at_top_ || coming <= kEndRev) {
        out_at_top_ = true;
        target = 0;
        if (command_ == 0 && at_rest) out.done = true;
      } else {
        const double scale = std::max(1.0, segment.retract_scale);
        target =
            -std::min({spindle.programmed_rps * scale * fo, cap, braking_speed(coming, brake, dt)});
      }
      break;
    }
    case Phase::stopping:
      target = 0;
      if (command_ == 0 && at_rest) out.done = true;
      break;
    default:
      break;
  }
  command_ = toward(command_, target, accel_ * dt);
  out.spindle_rps = direction_ * command_;
  sent_[sent_head_] = command_;
  sent_head_ = (sent_head_ + 1) % kMaxDelayPeriods;

  // Measured from the origin as it stands now (the lock may have just set it).
  const double progress = direction_ * (spindle.revolutions - origin_);
  const double ahead = direction_ * (spindle.revolutions + spindle.rps * dt - origin_);
  const bool locked = locked_;
  const double s_rev = locked ? std::clamp(ahead, 0.0, bottom) : 0.0;
  out.s = s_rev * per_rev;
  out.v = locked ? std::abs(spindle.rps) * per_rev : 0.0;
  status_.progress = locked ? progress : 0.0;
  if (status_.phase == Phase::tapping_out && out.done) {
    out.s = 0;
    out.v = 0;
  }

  // A position that jumps (an encoder that slipped or was reset, a wild reading) would throw
  // the axis: the axis stays where it was and the move stops.
  // A spindle that turns by the clock goes further over a servo period that came late.
  const double step_time = std::max(dt, spindle.elapsed_s);
  const double step_limit =
      kJumpShare * segment.axis_velocity * step_time + kJumpSlackRev * per_rev;
  if (locked && std::abs(out.s - last_s_) > step_limit) {
    out.error = RtEvent::Code::sync_jump;
    out.error_value = std::abs(progress - last_progress_);
    out.error_limit = step_limit / per_rev;
    out.s = last_s_;
    out.v = 0;
    return out;
  }
  last_s_ = out.s;
  // A spindle that runs on past either end would drag the tap off its thread: stopped.
  if (locked && (progress > bottom + kOverrunRev || progress < -kOverrunRev)) {
    out.error = RtEvent::Code::sync_overrun;
    out.error_value = progress > bottom ? progress - bottom : -progress;
    out.error_limit = kOverrunRev;
    return out;
  }
  // A spindle that is driven and does not turn.
  watch_stall(std::abs(command_) > 10.0 * kRestRps && std::abs(progress - last_progress_) < 1e-6,
              spindle, dt, out);
  last_progress_ = progress;
  return out;
}

SyncFollower::Step SyncFollower::thread_step(const Segment& segment, const Spindle& spindle,
                                             bool stop, double dt) noexcept {
  using Phase = SyncStatus::Phase;
  Step out;
  const double per_rev = segment.per_rev;
  const double length = segment.length;
  const double accel = segment.max_acceleration;
  const double ahead = direction_ * (spindle.revolutions + spindle.rps * dt - origin_);
  if (stop) status_.phase = Phase::stopping;
  if (status_.phase == Phase::index && ahead >= 0) status_.phase = Phase::following;
  status_.progress = ahead;

  double wanted = 0;
  if (status_.phase == Phase::following) {
    // Catch up with the helix as fast as the line allows, then ride it; slow to rest at the
    // line's end.
    const double target = ahead * per_rev;
    const double error = target - path_s_;
    const double helix_v = std::abs(spindle.rps) * per_rev;
    const double brake = kBrakeShare * accel;
    // Far from the helix the fastest catch-up that can still settle on it; near it a gentle
    // proportional pull (over kSettlePeriods periods), which does not chatter.
    const double pull = std::min(braking_speed(std::abs(error), brake, dt),
                                 std::abs(error) / (kSettlePeriods * dt));
    wanted = helix_v + std::copysign(pull, error);
    // The speed at the end of this period from which braking stops at the line's end, the
    // period's own way (at the mean of the two speeds) counted.
    const double room = 2.0 * brake * (length - path_s_) - brake * dt * path_v_;
    const double b_dt = brake * dt;
    const double to_end = 0.5 * (std::sqrt(b_dt * b_dt + 4.0 * std::max(0.0, room)) - b_dt);
    wanted = std::min({wanted, segment.axis_velocity, to_end});
    wanted = std::max(0.0, wanted);
  }
  if (status_.phase == Phase::stopping) wanted = 0;
  const double before = path_v_;
  path_v_ = toward(path_v_, wanted, accel * dt);
  path_s_ = std::min(length, path_s_ + 0.5 * (before + path_v_) * dt);
  out.s = path_s_;
  out.v = path_v_;
  if (path_s_ >= length - 1e-9) {
    out.s = length;
    out.done = true;
    helix_end_ = origin_ + direction_ * length / per_rev;
    has_helix_end_ = status_.phase == Phase::following;
  } else if (status_.phase == Phase::stopping && at_rest(path_v_)) {
    out.done = true;
  }
  // Waiting for a spindle that does not turn.
  watch_stall(status_.phase == Phase::index && std::abs(spindle.rps) <= kRestRps, spindle, dt, out);
  return out;
}

}  // namespace cncd::motion
