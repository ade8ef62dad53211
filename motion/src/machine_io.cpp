#include "cncd/motion/machine_io.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {

MachineIo::MachineIo(const config::MachineConfig& config, double period_s)
    : config_(config.spindle), period_s_(period_s), ideal_(!config.spindle.present) {
  spindle_.present = config.spindle.driver != config::SpindleDriver::none;
  spindle_.at_speed = true;
}

bool MachineIo::run(const IoAction& action, bool first) noexcept {
  using Kind = IoAction::Kind;
  switch (action.kind) {
    case Kind::none:
      return true;
    case Kind::spindle:
      end_orient();
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
    case Kind::orient_spindle:
      return orient(action, first);
    case Kind::wait_orient:
      return wait_orient(action, first);
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
    wait_ended_ = false;
  }
  if (!spindle_.enabled || at_speed() || (wait_ended_ && turning_as_told())) {
    wait_ = {};
    wait_ended_ = false;
    return true;
  }
  wait_ended_ = false;
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
    wait_ended_ = false;
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
  const bool timed_out = !met && (wait_ended_ || static_cast<double>(waited_) * period_s_ >=
                                                     std::max(0.0, action.timeout_s));
  wait_ended_ = false;
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
  end_orient();
  spindle_.direction = 0;
  spindle_.paused_off = false;
  resuming_ = false;
  coolant_held_ = false;
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
  wait_ended_ = false;
}

void MachineIo::end_wait(WaitStatus::Kind kind, std::uint64_t since) noexcept {
  if (kind != WaitStatus::Kind::none && wait_.kind == kind && wait_.since == since)
    wait_ended_ = true;
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

bool MachineIo::resume_requested() noexcept {
  if (coolant_held_) {
    coolant_held_ = false;
    io_.flood = out_.flood = held_flood_;
    io_.mist = out_.mist = held_mist_;
  }
  if (!spindle_.paused_off) return false;
  spindle_.paused_off = false;
  update_command();
  resuming_ = true;
  resume_waited_ = 0;
  return true;
}

void MachineIo::hold_at_rest(bool restore) noexcept {
  if (restore) {
    if (spindle_.direction != 0) spindle_.paused_off = true;
    if (io_.flood || io_.mist) {
      coolant_held_ = true;
      held_flood_ = io_.flood;
      held_mist_ = io_.mist;
    }
  } else {
    spindle_.direction = 0;
    spindle_.paused_off = false;
  }
  io_.flood = io_.mist = false;
  out_.flood = out_.mist = false;
  update_command();
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
