// S-curve path motion: each servo period picks the highest acceleration within a jerk step of
// the last one from which every speed limit ahead can still be kept under the jerk limit.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "cncd/motion/path_executor.hpp"
#include "profile.hpp"
#include "scurve.hpp"

namespace cncd::motion {
namespace {

// The limits are checked against braking that uses this share of the jerk limit, so that the
// period-by-period steps (which cannot switch the jerk within a period) have room to follow it.
constexpr double kPlanJerkShare = 0.98;
// Likewise the braking holds this share of the acceleration limit, so that a step whose linear
// change in acceleration lags a braking that reaches its limit within the period can brake
// harder and catch up.
constexpr double kPlanAccelShare = 0.98;
constexpr double kDistanceSlack = 1e-9;
// Binary search steps over one period's range of accelerations.
constexpr int kSearchSteps = 14;

}  // namespace

// Which limits bind, and with what braking. Every period picks a state from which every limit
// ahead can still be kept; that choice only exists next period if the set of such states does
// not shrink as the path advances or the window grows:
// - A limit at the end of segment m is kept by braking over the segments between the path and
//   it, so it brakes with `accel`, the smallest tangential limit of the segments from the
//   active one to m. The segment after m takes no part: `entry` (its own limit) is what an
//   acceleration must be ramped off to before it, and a braking to the limit's speed ends
//   with no acceleration there. As the path advances segments leave that minimum, which can
//   only rise; segments arriving in the window come after m. An earlier version took the
//   smallest limit up to the segment after m for both, so that one short tight blend slowed
//   every braking beyond it.
// - A limit m is implied (not "on") by a nearer limit j with w_j <= w_m: a step that passes j
//   leaves the path at most at w_j with its acceleration ramped to zero within w_j
//   (settle_speed), from where no braking is needed for m, and until then j comes first.
//   Whether it is depends on the two speeds alone, never on where the path stands; once j
//   is passed, m is on again from a state that meets it with nothing to brake.
void PathExecutor::gather_limits(double ds, double v, double a) noexcept {
  limit_count_ = 0;
  const double jerk = kPlanJerkShare * jerk_;
  const Segment& head = window_at(head_seq_);
  cap_hard_ = head.axis_velocity;
  cap_soft_ = std::min(cap_hard_, speed_limit(head));
  double distance = head.length - path_s_;
  // No limit beyond the distance in which the fastest next state stops with the smallest
  // acceleration limit in the window can bind (a limit brakes with no less).
  double brake = head.max_acceleration;  // the smallest limit up to the limit at hand
  const double horizon =
      ds + scurve::brake_distance(v, a, 0.0, kPlanAccelShare * window_floor_accel(), jerk) + 1e-6;
  double min_soft = 1e300;
  double min_hard = 1e300;
  double min_entry = 1e300;
  // A limit no faster than one nearer is implied by it (see above).
  auto implied = [&](double target, bool soft) { return target >= (soft ? min_soft : min_hard); };
  for (int k = 0; k < window_count_; ++k) {
    const std::uint64_t seq = head_seq_ + static_cast<std::uint64_t>(k);
    const Segment& seg = window_at(seq);
    double hard = 0;
    double soft = 0;
    double entry = 1e300;
    if (k + 1 < window_count_) {
      const Segment& next = window_at(seq + 1);
      if (seg.continuous && seg.kind != Segment::Kind::dwell && next.kind != Segment::Kind::dwell) {
        hard = std::min({seg.axis_velocity, next.axis_velocity, seg.junction_velocity});
        soft = std::min({hard, speed_limit(seg), speed_limit(next)});
        entry = next.max_acceleration;
      }
    }
    const bool soft_on = !implied(soft, true);
    const bool hard_on = !implied(hard, false);
    if (soft_on || hard_on || entry < min_entry) {
      if (limit_count_ == kMaxLimits) {
        // Out of room: the path stops at the last limit kept, a safe underestimate.
        SpeedLimit& last = limits_[static_cast<std::size_t>(kMaxLimits - 1)];
        last.soft = last.hard = 0;
        last.soft_on = last.hard_on = true;
        return;
      }
      limits_[static_cast<std::size_t>(limit_count_++)] = {distance, soft,    hard,   brake,
                                                           entry,    soft_on, hard_on};
    }
    min_soft = std::min(min_soft, soft);
    min_hard = std::min(min_hard, hard);
    min_entry = std::min(min_entry, entry);
    if (hard <= 0 || distance > horizon) return;
    const Segment& next = window_at(seq + 1);
    distance += next.length;
    brake = std::min(brake, next.max_acceleration);
  }
}

bool PathExecutor::keeps_limits(double v_before, double a_before, double v, double a, double ds,
                                bool soft, bool speeds_only) const noexcept {
  const double jerk = kPlanJerkShare * jerk_;
  const double cap = soft ? cap_soft_ : cap_hard_;
  if (scurve::settle_speed(v, std::max(a, 0.0), jerk) > cap * (1 + 1e-12) + 1e-12) return false;
  // Whether a nearer limit already brakes the path to its speed: that braking ends with no
  // acceleration at it, so the accelerations of the segments beyond it are met there.
  bool braked = false;
  for (int k = 0; k < limit_count_; ++k) {
    const SpeedLimit& limit = limits_[static_cast<std::size_t>(k)];
    const double room = limit.distance - ds + kDistanceSlack;
    const double target = soft ? limit.soft : limit.hard;
    const bool on = soft ? limit.soft_on : limit.hard_on;
    if (room < 0) {
      // Passed within the step: the speed and the acceleration there lie between the step's
      // two ends, and the segment after it must not be sped up past it.
      if (on && std::max(v_before, scurve::settle_speed(v, std::max(a, 0.0), jerk)) >
                    target * (1 + 1e-12) + 1e-12)
        return false;
      if (!speeds_only && std::max(std::abs(a_before), std::abs(a)) > limit.entry * (1 + 1e-12))
        return false;
      continue;
    }
    if (on && scurve::brake_distance(v, a, target, kPlanAccelShare * limit.accel, jerk) > room)
      return false;
    // Where the speed must come down to the limit's, the braking ends with no acceleration
    // there, and it was planned with at most `accel`: a harder deceleration must be eased to
    // that in time. Elsewhere an acceleration above what the segment after the limit allows
    // must be ramped off before it.
    const bool brakes = on && scurve::settle_speed(v, std::max(a, -limit.accel), jerk) > target;
    const double excess = std::abs(a) - (brakes ? limit.accel : limit.entry);
    if (excess > 0 && !braked && !(speeds_only && !brakes)) {
      const double t = excess / jerk;
      const double sign = a > 0 ? 1.0 : -1.0;
      if (t * (v + t * (a / 2.0 - sign * jerk * t / 6.0)) > room) return false;
    }
    braked = braked || brakes;
  }
  return true;
}

bool PathExecutor::eases_in_time(double v, double a, double ds) const noexcept {
  const double jerk = kPlanJerkShare * jerk_;
  for (int k = 0; k < limit_count_; ++k) {
    const SpeedLimit& limit = limits_[static_cast<std::size_t>(k)];
    const double excess = -a - limit.entry;
    if (excess <= 0) continue;
    const double room = limit.distance - ds + kDistanceSlack;
    const double t = excess / jerk;
    if (room < 0 || t * (v + t * (a / 2.0 + jerk * t / 6.0)) > room) return false;
  }
  return true;
}

void PathExecutor::scurve_step(double& dt, AxisPose& pose) noexcept {
  const Segment& head = window_at(head_seq_);
  const double accel = head.max_acceleration;
  const double v = path_v_;
  const double a = std::clamp(path_a_, -accel, accel);
  const double hi = std::min(accel, a + jerk_ * dt);
  // Far enough to hold every limit the next period's fastest state could need to slow for.
  const scurve::Step fastest = scurve::integrate(v, a, hi, dt);
  gather_limits(fastest.distance, fastest.velocity, hi);
  const double lo = std::max(-accel, a - jerk_ * dt);

  auto keeps = [&](double a_next, bool soft, bool speeds_only = false) {
    const scurve::Step step = scurve::integrate(v, a, a_next, dt);
    return keeps_limits(v, a, step.velocity, step.acceleration, step.distance, soft, speeds_only);
  };
  // The highest acceleration in [low, high] for which `ok` holds, given that it holds at low.
  auto highest = [&](double low, double high, auto ok) {
    for (int i = 0; i < kSearchSteps; ++i) {
      const double mid = 0.5 * (low + high);
      (ok(mid) ? low : high) = mid;
    }
    return low;
  };
  auto keeps_soft = [&](double x) { return keeps(x, true); };
  auto keeps_hard = [&](double x) { return keeps(x, false); };
  double a_next;
  if (keeps_soft(hi)) {
    a_next = hi;
  } else if (keeps_soft(lo)) {
    a_next = highest(lo, hi, keeps_soft);
  } else {
    // A lowered limit (override, hold, abort): slow down as hard as the jerk allows, easing
    // off so as to settle on the active segment's limit rather than under it; the axes' own
    // limits ahead still come first.
    a_next = lo;
    const auto settles_above = [&](double x) {
      const scurve::Step step = scurve::integrate(v, a, x, dt);
      return scurve::settle_speed(step.velocity, std::min(step.acceleration, 0.0), jerk_) >=
             cap_soft_;
    };
    if (v > cap_soft_) {
      // The lowest acceleration that still settles at or above the limit.
      double low = lo;
      double high = hi;
      if (settles_above(lo)) {
        high = lo;
      } else if (settles_above(hi)) {
        for (int i = 0; i < kSearchSteps; ++i) {
          const double mid = 0.5 * (low + high);
          (settles_above(mid) ? high : low) = mid;
        }
      }
      a_next = high;
    }
    if (!keeps_hard(a_next)) a_next = keeps_hard(lo) ? highest(lo, a_next, keeps_hard) : lo;
    // Never brake harder than a segment ahead allows by the time it is reached (dropping the
    // deceleration at a segment's start is a jump), unless easing off would break an axis
    // limit. Where no choice keeps them all, braking wins only where it keeps every speed
    // limit and easing off does not: too fast into a tight arc costs v^2/r, far more than a
    // brief excess of tangential acceleration at a segment's start.
    const auto eases = [&](double x) {
      const scurve::Step step = scurve::integrate(v, a, x, dt);
      return eases_in_time(step.velocity, step.acceleration, step.distance);
    };
    if (!eases(a_next)) {
      double low = a_next;
      double high = hi;
      if (eases(hi)) {
        for (int i = 0; i < kSearchSteps; ++i) {
          const double mid = 0.5 * (low + high);
          (eases(mid) ? high : low) = mid;
        }
      }
      const bool brakes_safer = keeps(a_next, false, true) && !keeps(high, false, true);
      if (keeps_hard(high) || (!keeps_hard(a_next) && !brakes_safer)) a_next = high;
    }
  }
  scurve::Step step = scurve::integrate(v, a, a_next, dt);
  dt = 0;

  // A stop ahead is landed on exactly: when this step would pass it (the limits were lowered
  // too late), or once the speed is down to what the last ramp of the acceleration to zero
  // covers within a period (v = j t^2 / 2 over a distance j t^3 / 6, t <= dt).
  const double last_ramp_v = jerk_ * period_s_ * period_s_ / 2;
  const double last_ramp_s = last_ramp_v * period_s_ / 3;
  for (int k = 0; k < limit_count_; ++k) {
    const SpeedLimit& limit = limits_[static_cast<std::size_t>(k)];
    if (limit.hard > 0) continue;
    const double gap = limit.distance - step.distance;
    if (gap <= 0 || (gap <= last_ramp_s + 1e-9 && step.velocity <= last_ramp_v)) {
      step = {limit.distance, 0.0, 0.0};
    }
    break;
  }
  if (at_rest(step.velocity) && step.acceleration <= 0) step = {step.distance, 0.0, 0.0};
  path_v_ = step.velocity;
  path_a_ = step.acceleration;

  // Along the segments the step covers.
  double s = path_s_ + step.distance;
  for (;;) {
    const Segment& active = window_at(head_seq_);
    if (s < active.length - 1e-12) break;
    s = std::max(0.0, s - active.length);
    pose = active.end;
    finish_front();
    if (window_count_ == 0) {
      path_v_ = path_a_ = 0;
      s = 0;
      break;
    }
    const Segment& next = window_at(head_seq_);
    if (next.kind == Segment::Kind::dwell || next.spindle_sync != SpindleSync::none) {
      path_v_ = path_a_ = 0;
      s = 0;
      break;  // the dwell (or the move in step with the spindle) starts with the next period
    }
    has_active_ = true;
    if (!starts_here(next, pose)) return;
    activate(next);
  }
  path_s_ = s;
  if (has_active_) pose = window_at(head_seq_).point_at(path_s_);
}

}  // namespace cncd::motion
