// MachineIo's M19: the spindle comes to rest, then turns to an angle from its zero (revolution
// 0 of its position) and holds there, steered by its position each period: the speed it is
// told is the least of the orientation's top speed, what still stops at the target at half the
// spindle's acceleration, and a proportional approach. It counts as oriented once within
// kToleranceRev of the target and at rest, and holds there until the next spindle action.
#include <algorithm>
#include <cmath>

#include "cncd/motion/machine_io.hpp"

namespace cncd::motion {
namespace {

constexpr double kOrientRpm = 60.0;            // the fastest an orientation turns the spindle
constexpr double kToleranceRev = 0.5 / 360.0;  // half a degree
constexpr double kApproachGain = 10.0;         // rev/s per revolution still to go

double wrap_fraction(double x) {
  return x - std::floor(x);
}

}  // namespace

bool MachineIo::orient(const IoAction& action, bool first) noexcept {
  if (first) {
    if (!spindle_.present) {
      RtEvent e;
      e.code = RtEvent::Code::no_spindle;
      error_ = e;
      has_error_ = true;
      return false;
    }
    spindle_.direction = 0;
    spindle_.paused_off = false;
    spindle_.orient = 1;
    spindle_.orient_deg = std::isfinite(action.value) ? action.value : 0.0;
    orient_mode_ = action.mode;
    orient_placed_ = false;
    orient_rps_ = 0;
    update_command();
    waited_ = 0;
    wait_ = {};
    wait_.kind = WaitStatus::Kind::spindle_orient;
    wait_.since = cycle_;
  }
  return orient_waited(action.timeout_s);
}

bool MachineIo::wait_orient(const IoAction& action, bool first) noexcept {
  if (spindle_.orient != 1) return true;
  if (first) {
    waited_ = 0;
    wait_ = {};
    wait_.kind = WaitStatus::Kind::spindle_orient;
    wait_.since = cycle_;
  }
  return orient_waited(action.timeout_s);
}

bool MachineIo::orient_waited(double timeout_s) noexcept {
  if (spindle_.orient != 1) {
    wait_ = {};
    return true;
  }
  ++waited_;
  const double limit_s = std::isfinite(timeout_s) ? std::max(0.0, timeout_s) : 0.0;
  if (static_cast<double>(waited_) * period_s_ < limit_s) return false;
  // LinuxCNC's orient fault: the program stops, the spindle with it.
  const double target = orient_placed_ ? orient_target_ : spindle_.orient_deg / 360.0;
  const double off = wrap_fraction(target - spindle_.revolutions + 0.5) - 0.5;
  RtEvent e;
  e.code = RtEvent::Code::spindle_not_oriented;
  e.error = std::abs(off) * 360.0;
  e.limit = spindle_.orient_deg;
  e.oldest_ago = static_cast<std::uint64_t>(std::llround(limit_s * 1000.0));
  error_ = e;
  has_error_ = true;
  wait_ = {};
  end_orient();
  update_command();
  return false;
}

void MachineIo::step_orient() noexcept {
  const double at_rest_rps = stopped_rpm() / 60.0;
  if (!spindle_.has_position) {
    // No position to steer by: it stays at rest until the wait runs out.
    orient_rps_ = 0;
    apply_orient();
    return;
  }
  if (!orient_placed_) {
    orient_rps_ = 0;
    if (std::abs(spindle_rps_) > at_rest_rps) {
      apply_orient();
      return;
    }
    // At rest: the turn to the angle, forward (M3's way, P0), in reverse (P1) or the shorter.
    const double forward = wrap_fraction(spindle_.orient_deg / 360.0 - spindle_.revolutions);
    const double reverse = forward > 0 ? forward - 1.0 : 0.0;
    double turn = forward;
    if (orient_mode_ == 1 || (orient_mode_ == 2 && -reverse < forward)) turn = reverse;
    orient_target_ = spindle_.revolutions + turn;
    orient_placed_ = true;
  }
  const double off = orient_target_ - spindle_.revolutions;
  double top_rps = kOrientRpm / 60.0;
  const double limit_rpm = std::min(config_.max_forward_velocity, config_.max_reverse_velocity);
  if (!ideal_ && limit_rpm > 0) top_rps = std::min(top_rps, limit_rpm / 60.0);
  double speed = std::min(top_rps, kApproachGain * std::abs(off));
  if (ideal_) {
    speed = std::min(top_rps, std::abs(off) / period_s_);  // the ideal spindle turns at once
  } else if (config_.acceleration > 0) {
    speed = std::min(speed, std::sqrt(config_.acceleration / 60.0 * std::abs(off)));
  }
  orient_rps_ = std::copysign(speed, off);
  if (spindle_.orient == 1 && std::abs(off) <= kToleranceRev &&
      std::abs(spindle_rps_) <= at_rest_rps) {
    spindle_.orient = 2;
  }
  apply_orient();
}

void MachineIo::apply_orient() noexcept {
  drive_at(orient_rps_);
}

void MachineIo::end_orient() noexcept {
  spindle_.orient = 0;
  orient_placed_ = false;
  orient_rps_ = 0;
}

}  // namespace cncd::motion
