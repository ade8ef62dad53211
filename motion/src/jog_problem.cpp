#include "jog_problem.hpp"

#include "cncd/motion/jog.hpp"

namespace cncd::motion {

// Why a jog cannot start now (checked before the servo thread sees it), or "".
std::string jog_problem(const config::MachineConfig& config, const Kinematics& kins,
                        const Status& status, int axis, double direction) {
  if (status.machine != MachineState::on) return "machine is not on";
  if (status.motion != MotionState::idle && status.motion != MotionState::jogging)
    return "the machine is moving";
  if (status.queued != 0) return "the machine is moving";
  if (status.panel.mpg_jogging) return "the panel's MPG is jogging";
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
