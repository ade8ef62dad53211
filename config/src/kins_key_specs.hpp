// The keys of the table-rotary kinematics (xyzac-trt-kins, xyzbc-trt-kins) and of tool centre
// point control, for config_keys.cpp's table (not installed). LinuxCNC sets the geometry with
// HAL pins (setp xyzac-trt-kins.x-rot-point ...); cncd has no HAL and reads the same names
// as [KINS] keys (docs/kinematics.md).
#pragma once

#include <array>

#include "key_makers.hpp"

namespace cncd::config::kins_keys {

using namespace key_makers;

constexpr std::array kKinsKeys{
    position_key("KINS", "X_ROT_POINT", "0",
                 "xyzac/xyzbc-trt-kins: X of the point where the C axis (the rotary table's) "
                 "crosses, from the machine's zero (LinuxCNC's x-rot-point pin)"),
    position_key("KINS", "Y_ROT_POINT", "0",
                 "xyzac/xyzbc-trt-kins: Y of the C axis's point (y-rot-point)"),
    position_key("KINS", "Z_ROT_POINT", "0",
                 "xyzac/xyzbc-trt-kins: Z of the C axis's point (z-rot-point)"),
    position_key("KINS", "X_OFFSET", "0",
                 "xyzbc-trt-kins: X from the C axis to the B (tilting) axis (x-offset)"),
    position_key("KINS", "Y_OFFSET", "0",
                 "xyzac-trt-kins: Y from the C axis to the A (tilting) axis (y-offset)"),
    position_key("KINS", "Z_OFFSET", "0",
                 "xyzac/xyzbc-trt-kins: Z from the C axis's point to the tilting axis (z-offset)"),
    position_key("KINS", "TOOL_OFFSET", "0",
                 "xyzac/xyzbc-trt-kins: length along the spindle from the tool tip, which TCP "
                 "keeps on the programmed path, to the controlled point while no G43 length is "
                 "in force; a G43 length replaces it (LinuxCNC nets the tool-offset pin to "
                 "motion.tooloffset.z)"),
    positive_key("TRAJ", "TCP_TOLERANCE", "0.005", "units",
                 "Under TCP (M428), how far the tool tip may leave a programmed line while the "
                 "rotary axes turn; moves are cut into joint-space pieces this close"),
};

}  // namespace cncd::config::kins_keys
