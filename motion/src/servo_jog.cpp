// The jog part of the servo loop: jog commands in, jogging axes advanced, their joints moved.
#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {

bool ServoLoop::axis_homed(int axis) const noexcept {
  const std::uint32_t joints = kins_->joints_of_axis(axis);
  for (int j = 0; j < joint_count_; ++j) {
    if ((joints & (1u << j)) != 0 && !joints_.homed[static_cast<std::size_t>(j)]) return false;
  }
  return joints != 0;
}

void ServoLoop::apply_jog(const Command& command) noexcept {
  Jog& jog = command.joint ? joint_jog_ : jog_;
  if (command.kind == Command::Kind::jog_stop) {
    jog.stop(command.axis);
    // A stop holds the MPG too: its target is forgotten, not resumed next period.
    if (!command.joint && command.axis == mpg_.axis) mpg_.drop = true;
    return;
  }
  const char* refusal = nullptr;
  if (status_.machine != MachineState::on) {
    refusal = "the machine is not on";
  } else if (path_.pending() || homing_.active()) {
    refusal = "the machine is moving";
  } else if (status_.panel.mpg_jogging) {
    refusal = "the panel's MPG is jogging";
  } else if (command.joint) {
    refusal = joint_jog_refusal(command);
  } else if (command.axis < 0 || command.axis >= kAxes) {
    refusal = "the machine has no such axis";
  } else if (joint_jog_.active()) {
    refusal = "a joint is jogging: axes jog once it rests";
  } else if (axis_joints_apart(command.axis)) {
    refusal = kJointsApartForJog;
  } else {
    sync_axes_from_joints();  // a jog starts from where the axis's joints stand
    const bool homed = axis_homed(command.axis);
    const double position = axis_pose_[static_cast<std::size_t>(command.axis)];
    refusal =
        command.kind == Command::Kind::jog_start
            ? jog_.start(command.axis, position, command.velocity, homed)
            : jog_.increment(command.axis, position, command.distance, command.velocity, homed);
  }
  if (refusal != nullptr) {
    warn(RtEvent::Code::jog_ignored, refusal);
    return;
  }
  status_.motion = MotionState::jogging;
}

bool ServoLoop::axis_joints_apart(int axis) const noexcept {
  return joints_apart_from_axis(*kins_, joints_.command, joint_count_, axis);
}

const char* ServoLoop::joint_jog_refusal(const Command& command) noexcept {
  const int joint = command.axis;
  if (joint < 0 || joint >= joint_count_) return "the machine has no such joint";
  if (jog_.active()) return "an axis is jogging: joints jog once it rests";
  const auto k = static_cast<std::size_t>(joint);
  const bool homed = joints_.homed[k];
  // A homed joint moves with its axis: alone it would leave its axis (a gantry's other joint,
  // corexy's other axis) where the axes' soft limits no longer hold.
  if (homed && !homed_joint_may_jog(*kins_, joint)) return kHomedJointMovesWithAxis;
  const double position = joints_.command[k];
  return command.kind == Command::Kind::jog_start
             ? joint_jog_.start(joint, position, command.velocity, homed)
             : joint_jog_.increment(joint, position, command.distance, command.velocity, homed);
}

void ServoLoop::advance_jog() noexcept {
  if (joint_jog_.active()) {
    // Joint mode: the joints move, the axes are where the forward kinematics put them.
    joint_jog_.update(joints_.command, period_s_);
    sync_axes_from_joints();
    status_.velocity = joint_jog_.speed();
    status_.motion = joint_jog_.active() ? MotionState::jogging : MotionState::idle;
    return;
  }
  // The axes that move this period (including the one that comes to rest in it).
  const std::uint32_t moving = jog_.active_mask();
  jog_.update(axis_pose_, period_s_);
  kins_->inverse(axis_pose_, moving, joints_.command);
  status_.velocity = jog_.speed();
  status_.motion = jog_.active() ? MotionState::jogging : MotionState::idle;
}

}  // namespace cncd::motion
