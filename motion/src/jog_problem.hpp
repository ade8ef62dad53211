// The checks a client's jog passes before the servo thread sees it (MotionController).
#pragma once

#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/jog.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/servo_loop.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

// Why a jog of `target` (an axis, or kJointJogBase + a joint) in `direction` cannot start now,
// or "": the machine is not on, other motion is under way, the panel's MPG is jogging, or the
// axis or joint is at its soft limit.
std::string jog_problem(const config::MachineConfig& config, const Kinematics& kins,
                        const Status& status, int target, double direction);

// Points a jog command at `target`.
inline void set_jog_target(Command& command, int target) {
  command.joint = target >= kJointJogBase;
  command.axis = command.joint ? target - kJointJogBase : target;
}

}  // namespace cncd::motion
