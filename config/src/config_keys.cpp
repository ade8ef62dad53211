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
          "Limit of the path jerk (S-curve profiles); 0 = unlimited (trapezoidal profiles)"},
  KeySpec{"TRAJ", "PLANNER_TYPE", integer, "", 0, 1, false, "", "",
          "0 = trapezoidal profiles; 1 = S-curve (needs MAX_LINEAR_JERK >= 1); unset: S-curve "
          "when MAX_LINEAR_JERK is set"},
  KeySpec{"TRAJ", "POSITION_FILE", path, "", 0, 0, false, "", "",
          "File that keeps joint positions across restarts; empty: start at zero"},
  KeySpec{"TRAJ", "NO_FORCE_HOMING", boolean, "0", 0, 0, false, "", "",
          "Allow programs and MDI before the machine is homed"},
  KeySpec{"KINS", "KINEMATICS", text, "", 0, 0, false, "", "",
          "Kinematics module and its arguments; only trivkins, e.g. trivkins coordinates=XYYZ"},
  KeySpec{"KINS", "JOINTS", integer, "", 1, 16, false, "", "", "Number of joints (motors)"},
  KeySpec{"DISPLAY", "MAX_FEED_OVERRIDE", real, "1.0", 0, 10, false, "ratio", "",
          "Highest feed override an operator may set; 1.2 = 120 %"},
  KeySpec{"DISPLAY", "MIN_SPINDLE_OVERRIDE", real, "1.0", 0, 10, false, "ratio", "",
          "Lowest spindle override an operator may set; 0.5 = 50 %"},
  KeySpec{"DISPLAY", "MAX_SPINDLE_OVERRIDE", real, "1.0", 0, 10, false, "ratio", "",
          "Highest spindle override an operator may set; 1.2 = 120 %"},
  KeySpec{"DISPLAY", "PROGRAM_PREFIX", path, "", 0, 0, false, "", "",
          "Directory programs are opened from, relative to this INI's directory (~ is $HOME); "
          "program.open refuses files outside it and [CNCD] PROGRAM_DIRS. Neither given: this "
          "INI's own directory"},
  KeySpec{"CNCD", "SOCKET", path, "/run/cncd/cncd.sock", 0, 0, false, "", "",
          "Unix socket that clients connect to"},
  KeySpec{"CNCD", "STATE_DIR", path, "", 0, 0, false, "", "",
          "Directory of the parameter, tool and position files given as relative paths; "
          "default $STATE_DIRECTORY under systemd, else $XDG_STATE_HOME/cncd/<INI name>"},
  KeySpec{"CNCD", "READ_GROUP", text, "", 0, 0, false, "", "",
          "Group whose members may read status; empty: only root and CONTROL_GROUP"},
  KeySpec{"CNCD", "CONTROL_GROUP", text, "", 0, 0, false, "", "",
          "Group whose members may command the machine; empty: only root"},
  KeySpec{"CNCD", "RT_PRIORITY", integer, "80", 1, 99, false, "", "",
          "SCHED_FIFO priority of the servo thread"},
  KeySpec{"CNCD", "RT_CPU", integer, "-1", -1, 1023, false, "", "",
          "CPU the servo thread is pinned to; -1 = any"},
  KeySpec{"CNCD", "PROGRAM_DIRS", path_list, "", 0, 0, false, "", "",
          "More directories programs may be opened from, colon-separated, relative to this "
          "INI's directory (~ is $HOME); see [DISPLAY] PROGRAM_PREFIX"},
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

  KeySpec{"GPIO", "CHIP", text, "", 0, 0, false, "", "",
          "GPIO chip of the step/dir lines: gpiochip0, /dev/gpiochip0, a label, or vcd:FILE to "
          "record the outputs to a value change dump instead of driving hardware"},
  KeySpec{"GPIO", "ESTOP_LINE", text, "", 0, 0, false, "", "",
          "Line (offset or name) of the external estop input; empty: none"},
  KeySpec{"GPIO", "ESTOP_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "The estop input is asserted at low level (normally closed to ground)"},
  KeySpec{"GPIO", "PROBE_LINE", text, "", 0, 0, false, "", "",
          "Line (offset or name) of the probe input; empty: none"},
  KeySpec{"GPIO", "PROBE_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "The probe input is asserted at low level"},
  KeySpec{"GPIO", "DEBOUNCE_NS", integer, "0", 0, 1'000'000'000, false, "ns", "",
          "A switch input must hold a new level this long before it counts; 0 = one base period"},
  KeySpec{"JOINT_n", "STEP_LINE", text, "", 0, 0, false, "", "",
          "gpio: line (offset or name) of the step output"},
  KeySpec{"JOINT_n", "DIR_LINE", text, "", 0, 0, false, "", "",
          "gpio: line of the direction output (high = negative direction)"},
  KeySpec{"JOINT_n", "ENABLE_LINE", text, "", 0, 0, false, "", "",
          "gpio: line of the drive enable output; empty: none"},
  KeySpec{"JOINT_n", "ENABLE_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "gpio: the enable output is low when the drive is enabled"},
  KeySpec{"JOINT_n", "HOME_SWITCH_LINE", text, "", 0, 0, false, "", "",
          "gpio: line of the home switch input; empty: none"},
  KeySpec{"JOINT_n", "HOME_SWITCH_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "gpio: the home switch reads low when pressed"},
  KeySpec{"JOINT_n", "MIN_LIMIT_LINE", text, "", 0, 0, false, "", "",
          "gpio: line of the minimum limit switch input; empty: none"},
  KeySpec{"JOINT_n", "MIN_LIMIT_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "gpio: the minimum limit switch reads low when tripped"},
  KeySpec{"JOINT_n", "MAX_LIMIT_LINE", text, "", 0, 0, false, "", "",
          "gpio: line of the maximum limit switch input; empty: none"},
  KeySpec{"JOINT_n", "MAX_LIMIT_ACTIVE_LOW", boolean, "0", 0, 0, false, "", "",
          "gpio: the maximum limit switch reads low when tripped"},
  KeySpec{"JOINT_n", "SIM_LAG", real, "0", 0, 10, false, "s", "",
          "sim: the simulated motor follows its command through a first-order lag of this time "
          "constant (to try the following-error limits); 0 = it is exactly where commanded"},
  KeySpec{"JOINT_n", "STEPLEN", integer, "1", 0, 100'000'000, false, "ns", "",
          "gpio: shortest time the step line is high (rounded up to base periods)"},
  KeySpec{"JOINT_n", "STEPSPACE", integer, "1", 0, 100'000'000, false, "ns", "",
          "gpio: shortest time the step line is low between steps"},
  KeySpec{"JOINT_n", "DIRSETUP", integer, "1", 0, 100'000'000, false, "ns", "",
          "gpio: shortest time between a direction change and the next step"},
  KeySpec{"JOINT_n", "DIRHOLD", integer, "1", 0, 100'000'000, false, "ns", "",
          "gpio: shortest time between the end of a step and a direction change"},
  KeySpec{"JOINT_n", "STEPGEN_MAXVEL", real, "0", 0, kInf, false, "units/s", "",
          "gpio: velocity limit of the step generator; 0 = only the step timing limits it"},
  KeySpec{"JOINT_n", "STEPGEN_MAXACCEL", real, "0", 0, kInf, false, "units/s^2", "",
          "gpio: acceleration limit of the step generator; 0 = unlimited"},
  KeySpec{"JOINT_n", "MODBUS", integer, "", 0, 99, false, "", "",
          "modbus: number n of the [MODBUS_n] bus the drive is on"},
  KeySpec{"JOINT_n", "SLAVE", integer, "", 1, 247, false, "", "",
          "modbus: unit identifier of the drive"},
  KeySpec{"JOINT_n", "TARGET_REGISTER", integer, "0", 0, 65535, false, "", "",
          "modbus: first holding register of the target position (counts)"},
  KeySpec{"JOINT_n", "CONTROL_REGISTER", integer, "2", 0, 65535, false, "", "",
          "modbus: holding register of the control word (bit 0 enable, bit 1 fault reset)"},
  KeySpec{"JOINT_n", "POSITION_REGISTER", integer, "0", 0, 65535, false, "", "",
          "modbus: first input register of the actual position (counts)"},
  KeySpec{"JOINT_n", "STATUS_REGISTER", integer, "2", 0, 65535, false, "", "",
          "modbus: input register of the status word (bit 0 ready, 1 enabled, 2 fault, "
          "3 in position)"},
  KeySpec{"JOINT_n", "REGISTER_WIDTH", choice, "32", 0, 0, false, "bits", "16|32",
          "modbus: positions are signed 16-bit (one register) or 32-bit (two registers)"},
  KeySpec{"JOINT_n", "WORD_ORDER", choice, "HIGH_FIRST", 0, 0, false, "",
          "HIGH_FIRST|LOW_FIRST", "modbus: which register of a 32-bit position comes first"},
  KeySpec{"MODBUS_n", "TRANSPORT", choice, "tcp", 0, 0, false, "", "tcp|rtu",
          "Modbus TCP (HOST, PORT) or RTU on a serial line (DEVICE, BAUD ...)"},
  KeySpec{"MODBUS_n", "HOST", text, "", 0, 0, false, "", "", "tcp: address of the drive(s)"},
  KeySpec{"MODBUS_n", "PORT", integer, "502", 1, 65535, false, "", "", "tcp: port"},
  KeySpec{"MODBUS_n", "DEVICE", text, "", 0, 0, false, "", "", "rtu: serial device, e.g. "
          "/dev/ttyUSB0"},
  KeySpec{"MODBUS_n", "BAUD", integer, "19200", 300, 4'000'000, false, "bit/s", "",
          "rtu: baud rate"},
  KeySpec{"MODBUS_n", "PARITY", choice, "N", 0, 0, false, "", "N|E|O",
          "rtu: parity: none, even or odd"},
  KeySpec{"MODBUS_n", "DATA_BITS", integer, "8", 5, 8, false, "", "", "rtu: data bits"},
  KeySpec{"MODBUS_n", "STOP_BITS", integer, "1", 1, 2, false, "", "", "rtu: stop bits"},
  KeySpec{"MODBUS_n", "TIMEOUT_MS", integer, "50", 1, 10'000, false, "ms", "",
          "Reply timeout of one request"},
  KeySpec{"MODBUS_n", "UPDATE_PERIOD_MS", integer, "10", 1, 10'000, false, "ms", "",
          "How often every drive on the bus gets its setpoint and is read back"},
  KeySpec{"MODBUS_n", "RETRIES", integer, "1", 0, 10, false, "", "",
          "Repeats of a failed request before the drive is faulted"},
};
// clang-format on

bool matches_section(std::string_view pattern, std::string_view section) {
  if (pattern == "JOINT_n") return section.starts_with("JOINT_") && section.size() > 6;
  if (pattern == "MODBUS_n") {
    return section.starts_with("MODBUS_") && section.size() > 7 &&
           section.find_first_not_of("0123456789", 7) == std::string_view::npos;
  }
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

std::string_view key_table_section(std::string_view section) {
  for (const auto& spec : kKeys) {
    if (matches_section(spec.section, section)) return spec.section;
  }
  return {};
}

}  // namespace cncd::config
