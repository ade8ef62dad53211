// The servo loop's side of the drivers (RT): feedback read and handed to the feedback checks,
// set-points guarded, commands written and recorded for late feedback.
#include <algorithm>
#include <cmath>

#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {

void ServoLoop::read_drivers() noexcept {
  drivers::MachineInputs inputs;
  drivers::IoFeedback io;
  for (auto& binding : drivers_) {
    drivers::JointFeedback block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    binding.driver->read(block, n);
    binding.driver->read_inputs(inputs);
    const bool had_spindle = io.spindle.present;
    binding.driver->read_io(io);
    if (!had_spindle && io.spindle.present) spindle_driver_ = binding.driver;
    for (int k = 0; k < n; ++k)
      feedback_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])] = block[k];
  }
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    joints_.feedback[k] = feedback_[k].position - joints_.motor_offset[k];
    joints_.home_switch[k] = feedback_[k].home_switch;
  }
  probe_input_ = inputs.probe;
  panel_in_ = io.panel;
  io_.set_cycle(cycle_);
  io_.feedback(io);
  if (inputs.estop && status_.machine != MachineState::estop) {
    stop_now(MachineState::estop);
    latch_fault(RtEvent::Code::estop_input);
  }
}

void ServoLoop::check_joints() noexcept {
  // Feedback counts once the drives have been sent the enable: a fault latched while they were
  // off is cleared by that enable edge, so judging it in the cycle that turns the machine on
  // would trip over the old fault again.
  if (status_.machine != MachineState::on || !drives_enabled_) return;
  std::uint32_t limits_ignored = 0;
  for (int j = 0; j < joint_count_; ++j) {
    if (homing_.ignores_limits(j)) limits_ignored |= 1u << j;
  }
  RtEvent fault;
  if (checks_.check(feedback_, cycle_, limits_ignored, fault)) return;
  status_.joint_fault[static_cast<std::size_t>(fault.joint)] = true;
  latch_fault(fault);
}

void ServoLoop::check_spindle() noexcept {
  if (status_.machine != MachineState::on || !drives_enabled_) return;
  RtEvent fault;
  if (!io_.drive_problem(fault)) return;
  if (spindle_driver_ != nullptr) spindle_driver_->fault_reason(fault.text, sizeof fault.text);
  latch_fault(fault);
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
    latch_fault(RtEvent::Code::set_point_not_finite, j);
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
  checks_.record(cycle_, commands_out_.data());
  drivers::IoCommand io = io_.command();
  io.panel = panel_lights();
  status_.panel.lights = io.panel;
  for (auto& binding : drivers_) {
    drivers::JointCommand block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    for (int k = 0; k < n; ++k)
      block[k] =
          commands_out_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])];
    binding.driver->write(block, n);
    binding.driver->write_io(io);
  }
}

}  // namespace cncd::motion
