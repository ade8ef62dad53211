// The checks a client's jog passes before the servo thread sees it (MotionController).
#pragma once

#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

// Why a jog of `axis` in `direction` cannot start now, or "": the machine is not on, other
// motion is under way, the panel's MPG is jogging, or the axis is at its soft limit.
std::string jog_problem(const config::MachineConfig& config, const Kinematics& kins,
                        const Status& status, int axis, double direction);

}  // namespace cncd::motion
