#include "jog_problem.hpp"

#include "cncd/motion/jog.hpp"

namespace cncd::motion {

// Why a jog cannot start now (checked before the servo thread sees it), or "".
std::string jog_problem(const config::MachineConfig& config, const Kinematics& kins,
                        const Status& status, int target, double direction) {
  if (status.machine != MachineState::on) return "machine is not on";
  if (status.motion != MotionState::idle && status.motion != MotionState::jogging)
    return "the machine is moving";
  if (status.queued != 0) return "the machine is moving";
  if (status.panel.mpg_jogging) return "the panel's MPG is jogging";
  if (target >= kJointJogBase) {
    const int joint = target - kJointJogBase;
    if (joint >= status.joint_count) return "the machine has no such joint";
    const auto k = static_cast<std::size_t>(joint);
    if (status.homed[k] && !homed_joint_may_jog(kins, joint)) return kHomedJointMovesWithAxis;
    const char* refusal =
        joint_jog_refusal(config, joint, status.joint_commanded[k], direction, status.homed[k]);
    return refusal != nullptr ? refusal : "";
  }
  const int axis = target;
  if (axis >= 0 && axis < kAxes &&
      joints_apart_from_axis(kins, status.joint_commanded, status.joint_count, axis))
    return kJointsApartForJog;
  const std::uint32_t joints = kins.joints_of_axis(axis);
  bool homed = false;
  for (int j = 0; j < status.joint_count; ++j) {
    if ((joints & (1u << j)) == 0) continue;
    homed = status.homed[static_cast<std::size_t>(j)];
    if (!homed) break;
  }
  const double position =
      axis >= 0 && axis < kAxes ? status.commanded[static_cast<std::size_t>(axis)] : 0.0;
  const char* refusal = jog_refusal(config, axis, position, direction, homed);
  return refusal != nullptr ? refusal : "";
}

}  // namespace cncd::motion
