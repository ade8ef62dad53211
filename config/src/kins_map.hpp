// [KINS] KINEMATICS and the joint map it gives (load_kins.cpp), for load_motion.
#pragma once

#include <string>

#include "cncd/config/machine_config.hpp"
#include "typed_reader.hpp"

namespace cncd::config {

struct KinsChoice {
  bool ok = false;      // a module cncd has, with arguments it could read
  bool corexy = false;  // corexykins: joints 0 and 1 are X + Y and X - Y
  // xyzac-trt-kins ('A') or xyzbc-trt-kins ('B'): joints X Y Z, the tilting axis and C; '\0'
  // for the others.
  char tilt = '\0';
  std::string module;
  std::string args;
  std::string coordinates;  // trivkins coordinates= letters, upper case; empty: not given
};

// The module [KINS] KINEMATICS names and its arguments; a problem for any other module.
KinsChoice load_kinematics(TypedReader& r);

// The axis letter each joint drives, in joint order ('\0': no axis of its own, a corexy motor
// or an extra joint), with the problems of JOINTS and [TRAJ] COORDINATES against it. trivkins:
// the letters of coordinates=, without it joint n drives the n-th of XYZABCUVW, and a gantry
// written only in [TRAJ] COORDINATES (XYYZ) is taken as that joint list. corexykins: joints 0
// and 1 are the X + Y and X - Y motors, joint n >= 2 the n-th of XYZABCUVW. Table-rotary:
// joints 0-4 are X Y Z A C (xyzac) or X Y Z B C (xyzbc).
std::string joint_map(TypedReader& r, const KinsChoice& k, MachineConfig& c);

// A table-rotary machine's geometry ([KINS] X_ROT_POINT ... TOOL_OFFSET) and [TRAJ]
// TCP_TOLERANCE; nothing for the other modules.
void load_table_rotary(TypedReader& r, const KinsChoice& k, MachineConfig& c);

}  // namespace cncd::config
