// The servo loop's side of the drivers (RT): feedback read and judged (faults, limit
// switches, the following error against the command the feedback answers), commands written
// and kept for late feedback.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {

void ServoLoop::read_drivers() noexcept {
  drivers::MachineInputs inputs;
  for (auto& binding : drivers_) {
    drivers::JointFeedback block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    binding.driver->read(block, n);
    binding.driver->read_inputs(inputs);
    for (int k = 0; k < n; ++k)
      feedback_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])] = block[k];
  }
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    joints_.feedback[k] = feedback_[k].position - joints_.motor_offset[k];
    joints_.home_switch[k] = feedback_[k].home_switch;
  }
  if (inputs.estop && status_.machine != MachineState::estop) {
    stop_now(MachineState::estop, nullptr);
    latch_fault("estop input asserted");
  }
}

void ServoLoop::check_joints() noexcept {
  // Feedback counts once the drives have been sent the enable: a fault latched while they were
  // off is cleared by that enable edge, so judging it in the cycle that turns the machine on
  // would trip over the old fault again.
  if (status_.machine != MachineState::on || !drives_enabled_) return;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& fb = feedback_[k];
    char text[240];  // latch_fault() keeps what fits in Status::fault_reason
    if (!std::isfinite(fb.position)) {
      status_.joint_fault[k] = true;
      std::snprintf(text, sizeof text, "joint %d: feedback position is not a number", j);
      latch_fault(text);
      return;
    }
    if (fb.fault || fb.stale) {
      status_.joint_fault[k] = true;
      // The driver may know more (which drive, register or line; why a bus went quiet).
      char detail[160] = {};
      if (joint_driver_[k] != nullptr) joint_driver_[k]->fault_reason(detail, sizeof detail);
      std::snprintf(text, sizeof text, "joint %d: %s%s%s", j,
                    fb.fault ? "drive fault" : "feedback is stale", detail[0] ? ": " : "", detail);
      latch_fault(text);
      return;
    }
    // A tripped limit switch stops everything, except while homing a joint configured to
    // ignore its limits (its home switch shares the limit input).
    if ((fb.min_limit || fb.max_limit) && !homing_.ignores_limits(j)) {
      status_.joint_fault[k] = true;
      std::snprintf(text, sizeof text, "joint %d: %s limit switch tripped", j,
                    fb.min_limit ? "minimum" : "maximum");
      latch_fault(text);
      return;
    }
    // LinuxCNC's limit: FERROR at full speed, scaled down with speed, never below MIN_FERROR;
    // measured from the commands the feedback answers, at their speed.
    const drivers::JointCommand newer = answered_command(k, fb.command_cycle);
    // Feedback answering a command sent while the drives were off: the drive followed nothing.
    if (!newer.enable) continue;
    drivers::JointCommand older = newer;
    // An older command sent with the drives off still counts: it followed the drive.
    if (fb.previous_cycle != 0 && fb.previous_cycle < newer.cycle)
      older = answered_command(k, fb.previous_cycle);
    const auto& joint = config_.joints[k];
    const double speed = std::max(std::abs(older.velocity), std::abs(newer.velocity));
    const double limit =
        std::max(joint.min_ferror, joint.ferror * speed / std::max(joint.max_velocity, 1e-9));
    const double low = std::min(older.position, newer.position);
    const double high = std::max(older.position, newer.position);
    const double error = std::max({low - fb.position, fb.position - high, 0.0});
    if (error > limit) {
      status_.joint_fault[k] = true;
      // Clamped: printing a huge number with %f would need a large buffer.
      const int n = std::snprintf(text, sizeof text, "joint %d: following error %.4f exceeds %.4f",
                                  j, std::min(error, 1e9), std::min(limit, 1e9));
      const auto ago = [this](std::uint64_t cycle) {
        return static_cast<unsigned long long>(cycle_ - 1 > cycle ? cycle_ - 1 - cycle : 0);
      };
      if (n > 0 && static_cast<std::size_t>(n) < sizeof text && ago(older.cycle) > 0) {
        const auto rest = sizeof text - static_cast<std::size_t>(n);
        if (older.cycle == newer.cycle) {
          std::snprintf(text + n, rest, " (against the command of %llu periods ago)",
                        ago(newer.cycle));
        } else {
          std::snprintf(text + n, rest, " (against the commands of %llu to %llu periods ago)",
                        ago(older.cycle), ago(newer.cycle));
        }
      }
      latch_fault(text);
      return;
    }
  }
}

drivers::JointCommand ServoLoop::answered_command(std::size_t k,
                                                  std::uint64_t cycle) const noexcept {
  if (cycle != 0 && cycle < cycle_) {
    if (const auto* command = history_.find(static_cast<int>(k), cycle)) return *command;
  }
  // The latest command (also when the driver names a cycle not written yet).
  drivers::JointCommand latest = commands_out_[k];
  latest.position = last_motor_cmd_[k];
  latest.enable = drives_enabled_;
  return latest;
}

void ServoLoop::guard_set_points() noexcept {
  bool held = false;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    if (std::isfinite(joints_.command[k] + joints_.motor_offset[k])) continue;
    // An offset or a first command taken from feedback that was not a number is none at all.
    if (!std::isfinite(joints_.motor_offset[k])) joints_.motor_offset[k] = 0;
    if (!std::isfinite(last_motor_cmd_[k])) last_motor_cmd_[k] = 0;
    joints_.command[k] = last_motor_cmd_[k] - joints_.motor_offset[k];
    status_.joint_fault[k] = true;
    held = true;
    char text[64];
    std::snprintf(text, sizeof text, "non-finite set-point on joint %d", j);
    latch_fault(text);
  }
  if (held) sync_axes_from_joints();
}

void ServoLoop::write_drivers() noexcept {
  const bool enable = status_.machine == MachineState::on;
  drives_enabled_ = enable;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const double motor = joints_.command[k] + joints_.motor_offset[k];
    commands_out_[k].velocity = (motor - last_motor_cmd_[k]) / period_s_;
    commands_out_[k].position = motor;
    commands_out_[k].enable = enable;
    commands_out_[k].cycle = cycle_;
    last_motor_cmd_[k] = motor;
  }
  history_.record(cycle_, commands_out_.data());
  for (auto& binding : drivers_) {
    drivers::JointCommand block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    for (int k = 0; k < n; ++k)
      block[k] =
          commands_out_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])];
    binding.driver->write(block, n);
  }
}

}  // namespace cncd::motion
