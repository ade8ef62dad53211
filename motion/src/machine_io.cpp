#include "cncd/motion/machine_io.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {

MachineIo::MachineIo(const config::MachineConfig& config, double period_s)
    : config_(config.spindle), period_s_(period_s), ideal_(!config.spindle.present) {
  spindle_.present = config.spindle.driver != config::SpindleDriver::none;
  spindle_.at_speed = true;
}

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
  out_.spindle.enable = spindle_.enabled;
  out_.spindle.reverse = spindle_.direction < 0;
  out_.spindle.rpm = rpm;
  if (ideal_) {
    spindle_.actual_rpm = rpm;
    spindle_.at_speed = true;
  }
  if (tapping_) apply_tap();
  // The new command against this period's speed: a spindle just started is not at speed yet.
  spindle_.at_speed = at_speed();
}

void MachineIo::apply_tap() noexcept {
  const double rpm = std::abs(tap_rps_) * 60.0;
  spindle_.enabled = spindle_.present;
  spindle_.commanded_rpm = rpm;
  out_.spindle.enable = spindle_.present;
  out_.spindle.reverse = tap_rps_ < 0;
  out_.spindle.rpm = rpm;
  if (ideal_) spindle_.actual_rpm = rpm;
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
  } else {
    spindle_.actual_rpm = spindle_.commanded_rpm;
    // The ideal spindle is where its command has taken it.
    spindle_rps_ = spindle_.present ? commanded_rps : 0.0;
    spindle_.has_position = spindle_.present;
    spindle_.revolutions += spindle_rps_ * period_s_;
  }
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

bool MachineIo::follow(const Segment& segment, bool first, double feed_override, bool stop,
                       double dt, double& s, double& v) noexcept {
  const SyncFollower::Spindle spindle = sync_spindle();
  if (first) {
    sync_.start(segment, spindle);
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
  const double want = spindle_.commanded_rpm;
  const double have = spindle_.actual_rpm;
  if (!spindle_.enabled) return have <= std::max(1.0, config_.at_speed_tolerance * 100.0);
  if (in_.spindle.has_at_speed) return in_.spindle.at_speed;
  return std::abs(have - want) <= config_.at_speed_tolerance * want;
}

bool MachineIo::run(const IoAction& action, bool first) noexcept {
  using Kind = IoAction::Kind;
  switch (action.kind) {
    case Kind::none:
      return true;
    case Kind::spindle:
      if (action.direction != 0 && !spindle_.present) {
        RtEvent e;
        e.code = RtEvent::Code::no_spindle;
        error_ = e;
        has_error_ = true;
        return false;
      }
      spindle_.direction = action.direction;
      if (std::isfinite(action.rpm) && action.rpm >= 0) spindle_.programmed_rpm = action.rpm;
      if (std::isfinite(action.css_numerator) && std::isfinite(action.css_max_rpm) &&
          std::isfinite(action.css_x_origin)) {
        spindle_.css_numerator = std::max(0.0, action.css_numerator);
        spindle_.css_max_rpm = std::max(0.0, action.css_max_rpm);
        spindle_.css_x_origin = action.css_x_origin;
      }
      update_command();
      return true;
    case Kind::spindle_override_enable:
      spindle_.override_enabled = action.on;
      update_command();
      return true;
    case Kind::coolant:
      io_.flood = action.flood;
      io_.mist = action.mist;
      out_.flood = action.flood;
      out_.mist = action.mist;
      return true;
    case Kind::digital_output:
      if (action.index >= 0 && action.index < kMaxDigitalIo) {
        const std::uint32_t bit = 1u << action.index;
        io_.douts = action.on ? io_.douts | bit : io_.douts & ~bit;
        out_.digital = io_.douts;
      }
      return true;
    case Kind::analog_output:
      if (action.index >= 0 && action.index < kMaxAnalogIo && std::isfinite(action.value)) {
        io_.aouts[static_cast<std::size_t>(action.index)] = action.value;
        out_.analog = io_.aouts;
      }
      return true;
    case Kind::wait_at_speed:
      return wait_at_speed(first);
    case Kind::wait_input:
      return wait_input(action, first);
    case Kind::hold:
      if (first) {
        released_ = false;
        wait_ = {};
        wait_.kind = action.hold == IoAction::Hold::tool_change ? WaitStatus::Kind::tool_change
                                                                : WaitStatus::Kind::user_m;
        wait_.hold_id = action.hold_id;
        wait_.since = cycle_;
      }
      if (released_ && released_id_ == action.hold_id) {
        released_ = false;
        wait_ = {};
        return true;
      }
      return false;
  }
  return true;
}

void MachineIo::not_at_speed() noexcept {
  RtEvent e;
  e.code = RtEvent::Code::spindle_not_at_speed;
  e.error = spindle_.actual_rpm;
  e.limit = spindle_.commanded_rpm;
  e.oldest_ago = static_cast<std::uint64_t>(std::llround(config_.at_speed_timeout_s * 1000.0));
  error_ = e;
  has_error_ = true;
}

bool MachineIo::wait_at_speed(bool first) noexcept {
  if (first) {
    waited_ = 0;
    wait_ = {};
    wait_.kind = WaitStatus::Kind::spindle_at_speed;
    wait_.since = cycle_;
  }
  if (!spindle_.enabled || at_speed()) {
    wait_ = {};
    return true;
  }
  ++waited_;
  if (static_cast<double>(waited_) * period_s_ >= config_.at_speed_timeout_s) {
    not_at_speed();
    wait_ = {};
  }
  return false;
}

double MachineIo::input_value(const IoAction& action) const noexcept {
  if (action.index < 0) return 0;
  if (action.digital) {
    if (action.index >= kMaxDigitalIo) return 0;
    return (in_.digital >> action.index) & 1u ? 1.0 : 0.0;
  }
  if (action.index >= kMaxAnalogIo) return 0;
  return in_.analog[static_cast<std::size_t>(action.index)];
}

bool MachineIo::wait_input(const IoAction& action, bool first) noexcept {
  const double value = input_value(action);
  const bool high = value != 0;
  if (first) {
    waited_ = 0;
    last_input_ = high;
    wait_ = {};
    wait_.kind = WaitStatus::Kind::input;
    wait_.index = action.index;
    wait_.digital = action.digital;
    wait_.since = cycle_;
  }
  // LinuxCNC's modes: 0 read at once, 1 rising edge, 2 falling edge, 3 high, 4 low.
  bool met = false;
  switch (action.digital ? action.mode : 0) {
    case 1:
      met = !first && high && !last_input_;
      break;
    case 2:
      met = !first && !high && last_input_;
      break;
    case 3:
      met = high;
      break;
    case 4:
      met = !high;
      break;
    default:
      met = true;
      break;
  }
  last_input_ = high;
  const bool timed_out =
      !met && static_cast<double>(waited_) * period_s_ >= std::max(0.0, action.timeout_s);
  ++waited_;
  if (!met && !timed_out) return false;
  input_result_ = met ? value : -1.0;
  ++input_waits_;
  wait_ = {};
  return true;
}

void MachineIo::started(const SyncOutputs& sync) noexcept {
  io_.douts = (io_.douts | sync.set) & ~sync.clear;
  out_.digital = io_.douts;
  for (int i = 0; i < kMaxAnalogIo; ++i) {
    if ((sync.analog_mask >> i) & 1u) {
      const double v = sync.analog[static_cast<std::size_t>(i)];
      if (std::isfinite(v)) io_.aouts[static_cast<std::size_t>(i)] = v;
    }
  }
  out_.analog = io_.aouts;
}

void MachineIo::stop_all() noexcept {
  spindle_.direction = 0;
  spindle_.paused_off = false;
  resuming_ = false;
  update_command();
  io_.flood = io_.mist = false;
  io_.douts = 0;
  io_.aouts = {};
  out_.flood = out_.mist = false;
  out_.digital = 0;
  out_.analog = {};
  cancel_wait();
}

void MachineIo::cancel_wait() noexcept {
  wait_ = {};
  released_ = false;
}

void MachineIo::release(std::uint32_t hold_id) noexcept {
  released_ = true;
  released_id_ = hold_id;
}

void MachineIo::set_override(double ratio) noexcept {
  if (!std::isfinite(ratio) || ratio < 0) return;
  spindle_.override_ratio = ratio;
  update_command();
}

void MachineIo::path_paused() noexcept {
  if (tapping_ || !config_.stop_on_pause || spindle_.direction == 0 || spindle_.paused_off) return;
  spindle_.paused_off = true;
  update_command();
}

void MachineIo::resume_requested() noexcept {
  if (!spindle_.paused_off) return;
  spindle_.paused_off = false;
  update_command();
  resuming_ = true;
  resume_waited_ = 0;
}

bool MachineIo::resume_ready() noexcept {
  if (!resuming_) return true;
  if (at_speed()) {
    resuming_ = false;
    wait_ = {};
    return true;
  }
  if (resume_waited_ == 0) {
    wait_ = {};
    wait_.kind = WaitStatus::Kind::spindle_at_speed;
    wait_.since = cycle_;
  }
  ++resume_waited_;
  if (static_cast<double>(resume_waited_) * period_s_ >= config_.at_speed_timeout_s) {
    not_at_speed();
    resuming_ = false;
    wait_ = {};
  }
  return false;
}

bool MachineIo::take_error(RtEvent& out) noexcept {
  if (!has_error_) return false;
  has_error_ = false;
  out = error_;
  return true;
}

bool MachineIo::drive_problem(RtEvent& out) const noexcept {
  if (!in_.spindle.present || !(in_.spindle.fault || in_.spindle.stale)) return false;
  out = {};
  out.code = in_.spindle.fault ? RtEvent::Code::spindle_fault : RtEvent::Code::spindle_stale;
  return true;
}

}  // namespace cncd::motion
