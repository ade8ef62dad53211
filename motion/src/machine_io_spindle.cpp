// MachineIo's spindle: the command the drive is told (with its sequence number), the speed
// and position as the driver reports them, the at-speed verdict, and the spindle as motion in
// step with it (G33, G33.1, rigid taps) sees and drives it.
#include <algorithm>
#include <cmath>

#include "cncd/motion/machine_io.hpp"

namespace cncd::motion {

void MachineIo::track_x(double x) noexcept {
  if (x == x_) return;
  x_ = x;
  if (spindle_.css_numerator > 0) update_command();
}

void MachineIo::update_command() noexcept {
  const bool on = spindle_.direction != 0 && !spindle_.paused_off;
  double rpm = spindle_.programmed_rpm;
  if (spindle_.css_numerator > 0) {
    // G96: the surface speed at the tool's radius, X from the spindle's axis.
    const double radius = std::abs(x_ - spindle_.css_x_origin);
    const double cap = spindle_.css_max_rpm > 0 ? spindle_.css_max_rpm : 1e300;
    rpm = radius > 1e-9 ? std::min(cap, spindle_.css_numerator / radius) : cap;
    if (!std::isfinite(rpm)) rpm = 0;
  }
  if (spindle_.override_enabled) rpm *= spindle_.override_ratio;
  if (!std::isfinite(rpm) || rpm < 0) rpm = 0;
  if (rpm == 0) {
    // S0 turns at no speed, whatever the minimum.
  } else if (spindle_.direction < 0) {
    rpm = std::clamp(rpm, config_.min_reverse_velocity,
                     std::max(config_.min_reverse_velocity, config_.max_reverse_velocity));
  } else {
    rpm = std::clamp(rpm, config_.min_forward_velocity,
                     std::max(config_.min_forward_velocity, config_.max_forward_velocity));
  }
  if (!on || !spindle_.present) rpm = 0;
  spindle_.enabled = on && spindle_.present;
  spindle_.commanded_rpm = rpm;
  command_spindle(spindle_.enabled, spindle_.direction < 0, rpm);
  if (ideal_) {
    spindle_.actual_rpm = rpm;
    spindle_.at_speed = true;
  }
  if (tapping_) apply_tap();
  if (spindle_.orient != 0) apply_orient();
  // The new command against this period's speed: a spindle just started is not at speed yet.
  spindle_.at_speed = at_speed();
}

void MachineIo::apply_tap() noexcept {
  drive_at(tap_rps_);
}

void MachineIo::drive_at(double rps) noexcept {
  // Enabled even at speed 0: the spindle is held, not let go.
  const double rpm = std::abs(rps) * 60.0;
  spindle_.enabled = spindle_.present;
  spindle_.commanded_rpm = rpm;
  command_spindle(spindle_.present, rps < 0, rpm);
  if (ideal_) spindle_.actual_rpm = rpm;
}

void MachineIo::command_spindle(bool enable, bool reverse, double rpm) noexcept {
  drivers::SpindleCommand& c = out_.spindle;
  if (c.enable == enable && c.reverse == reverse && c.rpm == rpm) return;
  if (enable) {
    // Told the other way while it may still turn the old one: a spindle that ramps passes
    // through rest on its way, and its speed alone does not say which way it turns.
    const int direction = reverse ? -1 : 1;
    if (turning_ != 0 && direction != turning_) reversing_ = true;
    turning_ = direction;
  }
  c.enable = enable;
  c.reverse = reverse;
  c.rpm = rpm;
  ++c.sequence;
}

bool MachineIo::acknowledged() const noexcept {
  return in_.spindle.acknowledged >= out_.spindle.sequence;
}

double MachineIo::stopped_rpm() const noexcept {
  return std::max(1.0, config_.at_speed_tolerance * 100.0);
}

void MachineIo::feedback(const drivers::IoFeedback& in) noexcept {
  in_ = in;
  elapsed_s_ = period_s_;
  io_.dins = in.digital;
  io_.ains = in.analog;
  const double commanded_rps =
      !out_.spindle.enable ? 0.0 : (out_.spindle.reverse ? -1.0 : 1.0) * out_.spindle.rpm / 60.0;
  if (in.spindle.present && !ideal_) {
    spindle_.actual_rpm = std::isfinite(in.spindle.rpm) ? std::abs(in.spindle.rpm) : 0.0;
    spindle_.has_position = in.spindle.has_position;
    spindle_.revolutions = std::isfinite(in.spindle.revolutions) ? in.spindle.revolutions : 0.0;
    if (spindle_.has_position && has_last_revolutions_) {
      // A spindle that turns by the clock (its driver says when it stood where) moved over the
      // time between its two positions: further over a servo period that came late, hardly at
      // all over one run straight after it. Too short a time tells no speed: the last stands.
      const std::int64_t at = in.spindle.time_ns;
      if (at != 0 && last_position_ns_ != 0) {
        elapsed_s_ = static_cast<double>(std::max<std::int64_t>(0, at - last_position_ns_)) * 1e-9;
      }
      if (elapsed_s_ >= 0.25 * period_s_) {
        spindle_rps_ = (spindle_.revolutions - last_revolutions_) / elapsed_s_;
      }
    } else {
      // No position: the speed it reports, in the direction it was told.
      spindle_rps_ = std::copysign(spindle_.actual_rpm / 60.0, commanded_rps);
    }
    has_last_revolutions_ = spindle_.has_position;
    last_revolutions_ = spindle_.revolutions;
    last_position_ns_ = in.spindle.time_ns;
    // A reversal is over once a reading taken after it shows the spindle at rest, or (with
    // its position) turning the new way. Without a ramp ([SPINDLE_0] ACCELERATION = 0) the
    // spindle is taken to turn the new way at once.
    if (reversing_ && acknowledged() &&
        (config_.acceleration <= 0 || spindle_.actual_rpm <= stopped_rpm() ||
         (spindle_.has_position && spindle_rps_ * turning_ > 0))) {
      reversing_ = false;
    }
  } else {
    spindle_.actual_rpm = spindle_.commanded_rpm;
    // The ideal spindle is where its command has taken it.
    spindle_rps_ = spindle_.present ? commanded_rps : 0.0;
    spindle_.has_position = spindle_.present;
    spindle_.revolutions += spindle_rps_ * period_s_;
  }
  if (spindle_.orient != 0) step_orient();
  spindle_.at_speed = at_speed();
}

SyncFollower::Spindle MachineIo::sync_spindle() const noexcept {
  SyncFollower::Spindle s;
  s.revolutions = spindle_.revolutions;
  s.rps = spindle_rps_;
  s.direction = spindle_.direction;
  s.programmed_rps = std::isfinite(spindle_.programmed_rpm) ? spindle_.programmed_rpm / 60.0 : 0.0;
  // A tap turns both ways: within the lower of the two limits.
  s.max_rps = std::min(config_.max_forward_velocity, config_.max_reverse_velocity) / 60.0;
  if (!(s.max_rps > 0)) s.max_rps = 1e300;
  s.acceleration = !ideal_ && config_.acceleration > 0 ? config_.acceleration / 60.0 : 1e300;
  s.stall_timeout_s = config_.at_speed_timeout_s;
  s.elapsed_s = elapsed_s_;
  if (!ideal_ && in_.spindle.command_delay_ns > 0) {
    s.command_delay_periods = static_cast<int>(
        std::lround(static_cast<double>(in_.spindle.command_delay_ns) * 1e-9 / period_s_));
  }
  return s;
}

bool MachineIo::follow(const Segment& segment, bool first, bool continues, double feed_override,
                       bool stop, double dt, double& s, double& v) noexcept {
  const SyncFollower::Spindle spindle = sync_spindle();
  if (first) {
    sync_.start(segment, spindle, continues);
    tapping_ = segment.spindle_sync == SpindleSync::tap;
  }
  const SyncFollower::Step step = sync_.step(segment, spindle, feed_override, stop, dt);
  if (tapping_) {
    tap_rps_ = step.spindle_rps;
    apply_tap();
  }
  s = step.s;
  v = step.v;
  if (step.error != RtEvent::Code::none) {
    // The program stops there (ServoLoop::advance_io), the spindle with it.
    RtEvent e;
    e.code = step.error;
    e.error = step.error_value;
    e.limit = step.error_limit;
    error_ = e;
    has_error_ = true;
    v = 0;
    return false;
  }
  return step.done;
}

void MachineIo::sync_ended() noexcept {
  sync_.end();
  ++syncs_done_;
  if (!tapping_) return;
  // The spindle turns again as the program has it.
  tapping_ = false;
  tap_rps_ = 0;
  update_command();
}

bool MachineIo::at_speed() const noexcept {
  if (ideal_ || !spindle_.present || !in_.spindle.present) return true;
  // A reading taken before the drive had the command tells of the old one: at speed, for a
  // VFD that still turns forward at the old speed after M4.
  if (!acknowledged()) return false;
  const double want = spindle_.commanded_rpm;
  const double have = spindle_.actual_rpm;
  if (!spindle_.enabled) return have <= stopped_rpm();
  // The drive judges its own speed against the command it has.
  if (in_.spindle.has_at_speed) return in_.spindle.at_speed;
  if (reversing_) return false;
  return std::abs(have - want) <= config_.at_speed_tolerance * want;
}

bool MachineIo::turning_as_told() const noexcept {
  if (!spindle_.enabled) return false;
  if (ideal_ || !spindle_.present || !in_.spindle.present) return true;
  return acknowledged() && !reversing_ && spindle_.actual_rpm > stopped_rpm();
}

}  // namespace cncd::motion
