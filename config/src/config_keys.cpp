#include "cncd/config/config_keys.hpp"

#include <array>

namespace cncd::config {
namespace {

constexpr double kInf = 1e308;
constexpr double kBig = 1e99;  // LinuxCNC writes +-1e99 for "no soft limit"

using enum KeyType;

// clang-format off
constexpr std::array kKeys{
  KeySpec{"EMC", "MACHINE", text, "", 0, 0, false, "", "", "Machine name shown to operators"},
  KeySpec{"EMCMOT", "SERVO_PERIOD", integer, "1000000", 50'000, 100'000'000, false, "ns", "",
          "Period of the servo (motion) thread"},
  KeySpec{"EMCMOT", "BASE_PERIOD", integer, "0", 0, 100'000'000, false, "ns", "",
          "Period of the fast base thread for software step generation; 0 = none. Must be "
          "shorter than SERVO_PERIOD"},
  KeySpec{"EMCMOT", "EMCMOT", text, "motmod", 0, 0, false, "", "",
          "Motion module; only its num_extrajoints=N argument is used"},
  KeySpec{"TASK", "CYCLE_TIME", real, "0.001", 0.0001, 1.0, false, "s",
          "", "Period of the task (program and command) loop"},
  KeySpec{"RS274NGC", "PARAMETER_FILE", path, "", 0, 0, false, "", "",
          "File that keeps the numbered parameters (#5161 ...) between runs; empty: none"},
  KeySpec{"RS274NGC", "RS274NGC_STARTUP_CODE", text, "", 0, 0, false, "", "",
          "G-code run when the interpreter starts, e.g. G17 G21 G40 G49 G54 G80 G90 G94"},
  KeySpec{"RS274NGC", "SUBROUTINE_PATH", path_list, "", 0, 0, false, "", "",
          "Colon-separated directories searched for O-word subroutine files"},
  KeySpec{"EMCIO", "TOOL_TABLE", path, "", 0, 0, false, "", "", "Tool table file"},
  KeySpec{"TRAJ", "COORDINATES", text, "XYZ", 0, 0, false, "", "",
          "Axis letters of the machine; a repeated letter is a gantry (X Y Y Z or XYYZ)"},
  KeySpec{"TRAJ", "LINEAR_UNITS", choice, "mm", 0, 0, false, "",
          "mm|metric|inch|in|imperial", "Machine units of linear axes (or 1.0 / 0.03937)"},
  KeySpec{"TRAJ", "ANGULAR_UNITS", choice, "degree", 0, 0, false, "",
          "degree|deg|radian|rad|grad|gon", "Machine units of rotary axes"},
  KeySpec{"TRAJ", "DEFAULT_LINEAR_VELOCITY", real, "1.0", 0, kInf, true, "units/s", "",
          "Initial jog and feed velocity"},
  KeySpec{"TRAJ", "MAX_LINEAR_VELOCITY", real, "", 0, kInf, true, "units/s", "",
          "Limit of the tool's path velocity; unset: the fastest linear axis"},
  KeySpec{"TRAJ", "DEFAULT_LINEAR_ACCELERATION", real, "", 0, kInf, true, "units/s^2", "",
          "Initial path acceleration; unset: MAX_LINEAR_ACCELERATION"},
  KeySpec{"TRAJ", "MAX_LINEAR_ACCELERATION", real, "", 0, kInf, true, "units/s^2", "",
          "Limit of the path acceleration; unset: the highest linear axis acceleration"},
  KeySpec{"TRAJ", "MAX_LINEAR_JERK", real, "0", 0, kInf, false, "units/s^3", "",
          "Limit of the path jerk; 0 = unlimited"},
  KeySpec{"TRAJ", "POSITION_FILE", path, "", 0, 0, false, "", "",
          "File that keeps joint positions across restarts; empty: start at zero"},
  KeySpec{"TRAJ", "NO_FORCE_HOMING", boolean, "0", 0, 0, false, "", "",
          "Allow programs and MDI before the machine is homed"},
  KeySpec{"KINS", "KINEMATICS", text, "", 0, 0, false, "", "",
          "Kinematics module and its arguments; only trivkins, e.g. trivkins coordinates=XYYZ"},
  KeySpec{"KINS", "JOINTS", integer, "", 1, 16, false, "", "", "Number of joints (motors)"},
  KeySpec{"DISPLAY", "MAX_FEED_OVERRIDE", real, "1.0", 0, 10, false, "ratio", "",
          "Highest feed override an operator may set; 1.2 = 120 %"},
  KeySpec{"CNCD", "SOCKET", path, "/run/cncd/cncd.sock", 0, 0, false, "", "",
          "Unix socket that clients connect to"},
  KeySpec{"CNCD", "READ_GROUP", text, "", 0, 0, false, "", "",
          "Group whose members may read status; empty: only root and CONTROL_GROUP"},
  KeySpec{"CNCD", "CONTROL_GROUP", text, "", 0, 0, false, "", "",
          "Group whose members may command the machine; empty: only root"},
  KeySpec{"CNCD", "RT_PRIORITY", integer, "80", 1, 99, false, "", "",
          "SCHED_FIFO priority of the servo thread"},
  KeySpec{"CNCD", "RT_CPU", integer, "-1", -1, 1023, false, "", "",
          "CPU the servo thread is pinned to; -1 = any"},
  KeySpec{"CNCD", "LOG_LEVEL", choice, "info", 0, 0, false, "",
          "trace|debug|info|warn|warning|error|critical|off", "Log verbosity"},

  KeySpec{"AXIS_L", "MIN_LIMIT", real, "-1e99", -kBig, kBig, false, "units", "",
          "Lowest position programs and jogs may reach (soft limit)"},
  KeySpec{"AXIS_L", "MAX_LIMIT", real, "1e99", -kBig, kBig, false, "units", "",
          "Highest position programs and jogs may reach (soft limit)"},
  KeySpec{"AXIS_L", "MAX_VELOCITY", real, "1.0", 0, kInf, true, "units/s", "",
          "Highest velocity of this axis"},
  KeySpec{"AXIS_L", "MAX_ACCELERATION", real, "1.0", 0, kInf, true, "units/s^2", "",
          "Highest acceleration of this axis"},
  KeySpec{"AXIS_L", "MAX_JERK", real, "0", 0, kInf, false, "units/s^3", "",
          "Highest jerk of this axis; 0 = unlimited"},

  KeySpec{"JOINT_n", "TYPE", choice, "LINEAR", 0, 0, false, "", "LINEAR|ANGULAR",
          "Whether the joint moves in linear or angular units"},
  KeySpec{"JOINT_n", "MIN_LIMIT", real, "", -kBig, kBig, false, "units", "",
          "Lowest joint position; unset: the axis MIN_LIMIT"},
  KeySpec{"JOINT_n", "MAX_LIMIT", real, "", -kBig, kBig, false, "units", "",
          "Highest joint position; unset: the axis MAX_LIMIT"},
  KeySpec{"JOINT_n", "MAX_VELOCITY", real, "1.0", 0, kInf, true, "units/s", "",
          "Highest velocity of this joint"},
  KeySpec{"JOINT_n", "MAX_ACCELERATION", real, "1.0", 0, kInf, true, "units/s^2", "",
          "Highest acceleration of this joint"},
  KeySpec{"JOINT_n", "FERROR", real, "1", 0, kInf, true, "units", "",
          "Following error limit at maximum velocity"},
  KeySpec{"JOINT_n", "MIN_FERROR", real, "", 0, kInf, true, "units", "",
          "Following error limit at standstill; unset: FERROR"},
  KeySpec{"JOINT_n", "BACKLASH", real, "0", 0, kInf, false, "units", "",
          "Backlash compensated when the joint reverses"},
  KeySpec{"JOINT_n", "HOME", real, "0", -kBig, kBig, false, "units", "",
          "Position the joint moves to after homing"},
  KeySpec{"JOINT_n", "HOME_OFFSET", real, "0", -kBig, kBig, false, "units", "",
          "Position of the home switch or index pulse"},
  KeySpec{"JOINT_n", "HOME_SEARCH_VEL", real, "0", -kInf, kInf, false, "units/s", "",
          "Velocity and direction of the home switch search; 0 = home where the joint is"},
  KeySpec{"JOINT_n", "HOME_LATCH_VEL", real, "0", -kInf, kInf, false, "units/s", "",
          "Velocity and direction of the slow latch move off the switch"},
  KeySpec{"JOINT_n", "HOME_FINAL_VEL", real, "-1", -kInf, kInf, false, "units/s", "",
          "Velocity of the move to HOME; negative: MAX_VELOCITY"},
  KeySpec{"JOINT_n", "HOME_USE_INDEX", boolean, "NO", 0, 0, false, "", "",
          "Latch on the encoder index pulse"},
  KeySpec{"JOINT_n", "HOME_INDEX_NO_ENCODER_RESET", boolean, "NO", 0, 0, false, "", "",
          "The encoder does not reset its count on the index pulse"},
  KeySpec{"JOINT_n", "HOME_IGNORE_LIMITS", boolean, "NO", 0, 0, false, "", "",
          "The home switch shares an input with a limit switch"},
  KeySpec{"JOINT_n", "HOME_IS_SHARED", boolean, "NO", 0, 0, false, "", "",
          "Several joints share one home switch input"},
  KeySpec{"JOINT_n", "HOME_SEQUENCE", integer, "", -16, 16, false, "", "",
          "Step of \"home all\"; unset: not homed by it; negative: home with the same step "
          "synchronised (gantry)"},
  KeySpec{"JOINT_n", "VOLATILE_HOME", boolean, "0", 0, 0, false, "", "",
          "Forget the home position when the machine is turned off"},
  KeySpec{"JOINT_n", "LOCKING_INDEXER", boolean, "0", 0, 0, false, "", "",
          "Rotary indexer that must be unlocked before it moves"},
  KeySpec{"JOINT_n", "HOME_ABSOLUTE_ENCODER", integer, "0", 0, 2, false, "", "",
          "Absolute encoder: 0 = no, 1 = home then move to HOME, 2 = home without moving"},
  KeySpec{"JOINT_n", "SCALE", real, "0", -kInf, kInf, false, "steps/unit", "",
          "Steps or counts per unit for the driver; 0 = not given"},
  KeySpec{"JOINT_n", "INPUT_SCALE", real, "0", -kInf, kInf, false, "counts/unit", "",
          "Encoder counts per unit (servo configs)"},
  KeySpec{"JOINT_n", "OUTPUT_SCALE", real, "0", -kInf, kInf, false, "", "",
          "Drive output per unit/s (servo configs)"},
  KeySpec{"JOINT_n", "DRIVER", choice, "sim", 0, 0, false, "", "sim|gpio|modbus",
          "Driver moving this joint: sim (simulated), gpio (step/dir), modbus"},
};
// clang-format on

bool matches_section(std::string_view pattern, std::string_view section) {
  if (pattern == "JOINT_n") return section.starts_with("JOINT_") && section.size() > 6;
  if (pattern == "AXIS_L") return section.starts_with("AXIS_") && section.size() == 6;
  return pattern == section;
}

}  // namespace

std::span<const KeySpec> key_table() {
  return kKeys;
}

const KeySpec* find_key_spec(std::string_view section, std::string_view key) {
  for (const auto& spec : kKeys) {
    if (spec.key == key && matches_section(spec.section, section)) return &spec;
  }
  return nullptr;
}

}  // namespace cncd::config
