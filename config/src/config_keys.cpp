#include "cncd/config/config_keys.hpp"

#include <array>

#include "key_makers.hpp"
#include "kins_key_specs.hpp"
#include "panel_key_specs.hpp"
#include "telemetry_key_specs.hpp"

namespace cncd::config {
namespace {

using namespace key_makers;

constexpr std::array kMachineKeys{
    text_key("EMC", "MACHINE", "", "Machine name shown to operators"),
    integer_key("EMCMOT", "SERVO_PERIOD", "1000000", 50'000, 100'000'000, "ns",
                "Period of the servo (motion) thread"),
    integer_key("EMCMOT", "BASE_PERIOD", "0", 0, 100'000'000, "ns",
                "Period of the fast base thread for software step generation; 0 = none. Must be "
                "shorter than SERVO_PERIOD"),
    text_key("EMCMOT", "EMCMOT", "motmod",
             "Motion module; only its num_extrajoints=N argument is used"),
    real_key("TASK", "CYCLE_TIME", "0.001", 0.0001, 1.0, "s",
             "Period of the task (program and command) loop"),
    path_key("RS274NGC", "PARAMETER_FILE", "",
             "File that keeps the numbered parameters (#5161 ...) between runs; empty: none"),
    text_key("RS274NGC", "RS274NGC_STARTUP_CODE", "",
             "G-code run when the interpreter starts, e.g. G17 G21 G40 G49 G54 G80 G90 G94"),
    path_list_key("RS274NGC", "SUBROUTINE_PATH",
                  "Colon-separated directories searched for O-word subroutine files"),
    path_list_key("RS274NGC", "USER_M_PATH",
                  "Colon-separated directories searched for user M-code programs (M100-M199), "
                  "relative to this INI's directory, after the first program directory "
                  "([DISPLAY] PROGRAM_PREFIX)"),
    choice_key("RS274NGC", "DIALECT", "linuxcnc", "linuxcnc|numeryx",
               "How programs are read: linuxcnc (LinuxCNC's RS274NGC) or numeryx (the Numeryx "
               "drilling dialect); a program's first line \"(dialect NAME)\" overrides it"),
    positive_key("RS274NGC", "NUMERYX_CLEARANCE", "", "units",
                 "Numeryx dialect: the height above R a cycle starts its feed at (R1 = R + "
                 "clearance); unset: 1 mm in a G21 program, 0.04 in in a G20 one"),
    bool_key("RS274NGC", "RIGID_TAPPING", "0",
             "G84 and G74 tap in step with the spindle (pitch F in G95, F/S in G94), as Fanuc "
             "and Numeryx machines do; 0: LinuxCNC's floating-holder cycles"),
    path_key("EMCIO", "TOOL_TABLE", "", "Tool table file"),
    text_key("EMCIO", "TOOL_CHANGE_POSITION", "",
             "Machine position M6 moves to before the tool change: 3 (X Y Z), 6 (X Y Z A B C) "
             "or 9 (X Y Z A B C U V W) numbers in machine units; empty: change where it stands"),
    bool_key("EMCIO", "TOOL_CHANGE_QUILL_UP", "0", "M6 first moves Z to machine zero (G53 G0 Z0)"),
    bool_key("EMCIO", "TOOL_CHANGE_WITH_SPINDLE_ON", "0",
             "The spindle keeps turning during a tool change (lathes, work in the spindle)"),
    text_key("TRAJ", "COORDINATES", "XYZ",
             "Axis letters of the machine; a repeated letter is a gantry (X Y Y Z or XYYZ)"),
    choice_key("TRAJ", "LINEAR_UNITS", "mm", "mm|metric|inch|in|imperial",
               "Machine units of linear axes (or 1.0 / 0.03937)"),
    choice_key("TRAJ", "ANGULAR_UNITS", "degree", "degree|deg|radian|rad|grad|gon",
               "Machine units of rotary axes"),
    positive_key("TRAJ", "DEFAULT_LINEAR_VELOCITY", "1.0", "units/s",
                 "Initial jog and feed velocity"),
    positive_key("TRAJ", "MAX_LINEAR_VELOCITY", "", "units/s",
                 "Limit of the tool's path velocity; unset: the fastest linear axis"),
    positive_key("TRAJ", "DEFAULT_LINEAR_ACCELERATION", "", "units/s^2",
                 "Initial path acceleration; unset: MAX_LINEAR_ACCELERATION"),
    positive_key("TRAJ", "MAX_LINEAR_ACCELERATION", "", "units/s^2",
                 "Limit of the path acceleration; unset: the highest linear axis acceleration"),
    real_key("TRAJ", "MAX_LINEAR_JERK", "0", 0, kInf, "units/s^3",
             "Limit of the path jerk (S-curve profiles); 0 = unlimited (trapezoidal profiles)"),
    integer_key(
        "TRAJ", "PLANNER_TYPE", "", 0, 1, "",
        "0 = trapezoidal profiles; 1 = S-curve (needs MAX_LINEAR_JERK >= 1); unset: S-curve "
        "when MAX_LINEAR_JERK is set"),
    path_key("TRAJ", "POSITION_FILE", "",
             "File that keeps joint positions across restarts; empty: start at zero"),
    bool_key("TRAJ", "NO_FORCE_HOMING", "0", "Allow programs and MDI before the machine is homed"),
    text_key("KINS", "KINEMATICS", "",
             "Kinematics module and its arguments: trivkins (e.g. trivkins coordinates=XYYZ, a "
             "gantry), corexykins (joint 0 = X + Y, joint 1 = X - Y), xyzac-trt-kins or "
             "xyzbc-trt-kins (a tilting rotary table, TCP with M428); docs/kinematics.md"),
    integer_key("KINS", "JOINTS", "", 1, 16, "", "Number of joints (motors)"),
    real_key("DISPLAY", "MAX_FEED_OVERRIDE", "1.0", 0, 10, "ratio",
             "Highest feed override an operator may set; 1.2 = 120 %"),
    real_key("DISPLAY", "MIN_SPINDLE_OVERRIDE", "1.0", 0, 10, "ratio",
             "Lowest spindle override an operator may set; 0.5 = 50 %"),
    real_key("DISPLAY", "MAX_SPINDLE_OVERRIDE", "1.0", 0, 10, "ratio",
             "Highest spindle override an operator may set; 1.2 = 120 %"),
    path_key("DISPLAY", "PROGRAM_PREFIX", "",
             "Directory programs are opened from, relative to this INI's directory (~ is $HOME); "
             "program.open refuses files outside it and [CNCD] PROGRAM_DIRS. Neither given: this "
             "INI's own directory"),
    path_key("CNCD", "SOCKET", "/run/cncd/cncd.sock", "Unix socket that clients connect to"),
    path_key("CNCD", "STATE_DIR", "",
             "Directory of the parameter, tool and position files given as relative paths; "
             "default $STATE_DIRECTORY under systemd, else $XDG_STATE_HOME/cncd/<INI name>"),
    path_key("CNCD", "PROBE_DIR", "",
             "Directory the (PROBEOPEN name) result files go to, relative to the state directory; "
             "default probe/ in the state directory, created (mode 0750) when first needed"),
    text_key("CNCD", "READ_GROUP", "",
             "Group whose members may read status; empty: only root and CONTROL_GROUP"),
    text_key("CNCD", "CONTROL_GROUP", "",
             "Group whose members may command the machine; empty: only root"),
    integer_key("CNCD", "MAX_CONNECTIONS", "1000", 2, 1000000, "",
                "Most control socket connections kept at once; lowered to fit the process's "
                "RLIMIT_NOFILE (less 32). Past it a new connection gets error 1010 and is closed"),
    integer_key("CNCD", "MAX_CONNECTIONS_PER_USER", "128", 1, 1000000, "",
                "Most connections one user may hold; root and cncd's own user have no such cap"),
    integer_key("CNCD", "CONTROL_RESERVE", "8", 1, 1000000, "",
                "Connections of MAX_CONNECTIONS that only root, cncd's own user and "
                "CONTROL_GROUP may take, so that an estop can always connect"),
    integer_key("CNCD", "RT_PRIORITY", "80", 1, 99, "", "SCHED_FIFO priority of the servo thread"),
    integer_key("CNCD", "RT_CPU", "-1", -1, 1023, "",
                "CPU the servo thread is pinned to; -1 = any"),
    path_list_key("CNCD", "PROGRAM_DIRS",
                  "More directories programs may be opened from, colon-separated, relative to this "
                  "INI's directory (~ is $HOME); see [DISPLAY] PROGRAM_PREFIX"),
    choice_key("CNCD", "LOG_LEVEL", "info", "trace|debug|info|warn|warning|error|critical|off",
               "Log verbosity"),
    signal_key("CNCD", "FLOOD_OUTPUT", "Digital output turned on by M8 (flood coolant)"),
    signal_key("CNCD", "MIST_OUTPUT", "Digital output turned on by M7 (mist coolant)"),
    signal_key("CNCD", "DIGITAL_OUTPUT_n",
               "Digital output n (0-31) that M62-M65 set and clear: gpio, coil or sim"),
    signal_key("CNCD", "ANALOG_OUTPUT_n",
               "Analog output n (0-15) that M67/M68 write: holding register or sim"),
    signal_key("CNCD", "DIGITAL_INPUT_n",
               "Digital input n (0-31) that M66 P waits for or reads: gpio, di, coil or sim"),
    signal_key("CNCD", "PROBE_INPUT",
               "Probe input G38.2-G38.5 stop on: gpio:LINE (read without debounce in the base "
               "thread) or sim:NAME; Modbus answers too late to stop on contact"),
    signal_key("CNCD", "ANALOG_INPUT_n",
               "Analog input n (0-15) that M66 E reads: input or holding register, or sim"),
    real_key("CNCD", "RUN_FROM_LINE_SAFE_Z", "", -kInf, kInf, "machine units",
             "Run from a line: the height (machine coordinates) Z rises to before X and Y move "
             "over the line's start; empty: [AXIS_Z] MAX_LIMIT"),
    positive_key("CNCD", "USER_M_TIMEOUT", "60", "s",
                 "A user M code (M100-M199) still running after this long is stopped and the "
                 "program with it"),

    text_key("WEB", "LISTEN", "127.0.0.1",
             "cncd-web: the IP address it listens on; 127.0.0.1 (this machine only), 0.0.0.0 or "
             ":: (every address) or one interface's address"),
    integer_key("WEB", "PORT", "8080", 1, 65535, "", "cncd-web: the TCP port of the page and /ws"),
    path_key("WEB", "PROGRAM_DIR", "",
             "cncd-web: where uploads go and programs are listed from; one of cncd's program "
             "directories ([DISPLAY] PROGRAM_PREFIX, [CNCD] PROGRAM_DIRS); default: the first"),
    integer_key("WEB", "MAX_UPLOAD_MB", "64", 1, 65536, "MiB",
                "cncd-web: the largest program an upload may bring"),
    path_key("WEB", "USERS_FILE", "",
             "cncd-web: the users, roles and password and API key hashes (mode 0600), relative to "
             "the state directory; default web-users in the state directory"),
    path_key("WEB", "TLS_CERT", "",
             "cncd-web: PEM certificate (chain) for HTTPS, with TLS_KEY; neither: plain HTTP"),
    path_key("WEB", "TLS_KEY", "", "cncd-web: PEM private key of TLS_CERT"),
    text_key("WEB", "ALLOWED_ORIGINS", "",
             "cncd-web: origins besides the page's own that browsers may send state-changing "
             "requests and WebSockets from, scheme://host[:port], separated by blanks or commas"),
    integer_key("WEB", "SESSION_HOURS", "12", 1, 8760, "h", "cncd-web: how long a login lasts"),
    integer_key("WEB", "MAX_CLIENTS", "64", 1, 100000, "",
                "cncd-web: most WebSocket connections at once"),
    real_key("WEB", "JOG_HEARTBEAT", "0.25", 0.05, 5, "s",
             "cncd-web: a continuous jog from the page stops this long after the page's last "
             "heartbeat (tab closed, network lost)"),

    choice_key("SPINDLE_0", "DRIVER", "sim", "none|sim|gpio|modbus",
               "What turns the spindle: none (the machine has none), sim (simulated), gpio "
               "(enable, direction and PWM lines), modbus (a VFD)"),
    real_key("SPINDLE_0", "MAX_FORWARD_VELOCITY", "", 0, kInf, "rpm",
             "Fastest forward speed; faster commands are lowered to it; unset: no limit"),
    real_key("SPINDLE_0", "MIN_FORWARD_VELOCITY", "0", 0, kInf, "rpm",
             "Slowest forward speed; slower commands (but 0) are raised to it"),
    real_key("SPINDLE_0", "MAX_REVERSE_VELOCITY", "", -kInf, kInf, "rpm",
             "Fastest reverse speed, a magnitude (-500 reads as 500, as in LinuxCNC); 0 = never "
             "in reverse; unset: MAX_FORWARD_VELOCITY"),
    real_key("SPINDLE_0", "MIN_REVERSE_VELOCITY", "", -kInf, kInf, "rpm",
             "Slowest reverse speed, a magnitude; unset: MIN_FORWARD_VELOCITY"),
    positive_key("SPINDLE_0", "INCREMENT", "100", "rpm",
                 "Step of the faster/slower commands of a user interface"),
    real_key("SPINDLE_0", "ACCELERATION", "0", 0, kInf, "rpm/s",
             "How fast the sim and PWM spindles change speed; 0 = at once"),
    real_key("SPINDLE_0", "AT_SPEED_TOLERANCE", "0.05", 0, 1, "ratio",
             "The spindle is at speed within this fraction of the commanded speed"),
    positive_key("SPINDLE_0", "AT_SPEED_TIMEOUT", "10", "s",
                 "A spindle not at speed this long after a command stops the program"),
    bool_key("SPINDLE_0", "STOP_ON_PAUSE", "0",
             "A pause stops the spindle; resume starts it again and waits until it is at speed"),
    signal_key("SPINDLE_0", "ENABLE",
               "gpio: digital output on while the spindle turns; a bare line (17, !17, GPIO17) "
               "is a gpio line"),
    signal_key("SPINDLE_0", "DIRECTION", "gpio: digital output on for reverse (M4)"),
    signal_key("SPINDLE_0", "PWM",
               "gpio: output the base thread pulses with a duty cycle for the speed"),
    real_key("SPINDLE_0", "PWM_FREQUENCY", "1000", 0.001, 1e6, "Hz",
             "gpio: PWM frequency; a period spans whole base periods"),
    real_key("SPINDLE_0", "PWM_MIN_DUTY", "0", 0, 1, "ratio",
             "gpio: duty cycle at 0 rpm; duty = PWM_MIN_DUTY + (1 - PWM_MIN_DUTY) x speed / "
             "MAX_FORWARD_VELOCITY"),
    signal_key("SPINDLE_0", "ENCODER_A", "gpio: encoder channel A input (with ENCODER_B)"),
    signal_key("SPINDLE_0", "ENCODER_B", "gpio: encoder channel B input (with ENCODER_A)"),
    signal_key("SPINDLE_0", "ENCODER_INDEX", "gpio: encoder index input, once a revolution"),
    integer_key("SPINDLE_0", "ENCODER_PPR", "0", 0, 1'000'000, "pulses/rev",
                "gpio: encoder pulses a revolution on each channel (4 counts each); 0 = none"),
    integer_key("SPINDLE_0", "MODBUS", "", 0, 99, "",
                "modbus: number n of the [MODBUS_n] bus the VFD is on"),
    integer_key("SPINDLE_0", "SLAVE", "1", 1, 247, "", "modbus: unit identifier of the VFD"),
    positive_key("SPINDLE_0", "SPEED_SCALE", "1", "",
                 "modbus: speed register value per rpm (register = rpm x SPEED_SCALE)"),
    register_key("SPINDLE_0", "COMMAND_REGISTER", "0",
                 "modbus: holding register of the run command (COMMAND_STOP/FORWARD/REVERSE)"),
    register_key("SPINDLE_0", "SPEED_REGISTER", "1",
                 "modbus: holding register of the commanded speed"),
    integer_key("SPINDLE_0", "ACTUAL_SPEED_REGISTER", "0", -1, 65535, "",
                "modbus: register of the actual speed, in ACTUAL_SPEED_TABLE; -1 = none"),
    integer_key("SPINDLE_0", "STATUS_REGISTER", "1", -1, 65535, "",
                "modbus: register of the status bits, in STATUS_TABLE; -1 = none"),
    choice_key("SPINDLE_0", "ACTUAL_SPEED_TABLE", "ir", "ir|hr",
               "modbus: the actual speed is an input (ir) or holding (hr) register"),
    choice_key("SPINDLE_0", "STATUS_TABLE", "ir", "ir|hr",
               "modbus: the status is an input (ir) or holding (hr) register"),
    register_key("SPINDLE_0", "COMMAND_STOP", "0", "modbus: command register value to stop"),
    register_key("SPINDLE_0", "COMMAND_FORWARD", "1",
                 "modbus: command register value to run forward"),
    register_key("SPINDLE_0", "COMMAND_REVERSE", "2",
                 "modbus: command register value to run in reverse"),
    integer_key("SPINDLE_0", "RUNNING_BIT", "0", -1, 15, "",
                "modbus: status bit set while the motor turns; -1 = none"),
    integer_key("SPINDLE_0", "AT_SPEED_BIT", "1", -1, 15, "",
                "modbus: status bit set at the commanded speed; -1 = none"),
    integer_key("SPINDLE_0", "FAULT_BIT", "2", -1, 15, "",
                "modbus: status bit set when the VFD has tripped; -1 = none"),
    integer_key("SPINDLE_0", "POSITION_REGISTER", "-1", -1, 65535, "",
                "modbus: first register of the shaft's position counter, in POSITION_TABLE, for "
                "spindle-synchronized motion (G33, G33.1, rigid tapping); -1 = none"),
    choice_key("SPINDLE_0", "POSITION_TABLE", "ir", "ir|hr",
               "modbus: the position is in input (ir) or holding (hr) registers"),
    choice_key("SPINDLE_0", "POSITION_WIDTH", "32", "16|32",
               "modbus: the position counter is 16 bits (one register) or 32 (two); it may wrap",
               "bits"),
    choice_key("SPINDLE_0", "WORD_ORDER", "HIGH_FIRST", "HIGH_FIRST|LOW_FIRST",
               "modbus: which register of a 32-bit position comes first"),
    real_key("SPINDLE_0", "POSITION_SCALE", "", -kInf, kInf, "counts/rev",
             "modbus: position counts a revolution; negative when the count goes down turning "
             "forward (M3)"),

    position_key("AXIS_L", "MIN_LIMIT", "-1e99",
                 "Lowest position programs and jogs may reach (soft limit)"),
    position_key("AXIS_L", "MAX_LIMIT", "1e99",
                 "Highest position programs and jogs may reach (soft limit)"),
    positive_key("AXIS_L", "MAX_VELOCITY", "1.0", "units/s", "Highest velocity of this axis"),
    positive_key("AXIS_L", "MAX_ACCELERATION", "1.0", "units/s^2",
                 "Highest acceleration of this axis"),
    real_key("AXIS_L", "MAX_JERK", "0", 0, kInf, "units/s^3",
             "Highest jerk of this axis; 0 = unlimited"),

    choice_key("JOINT_n", "TYPE", "LINEAR", "LINEAR|ANGULAR",
               "Whether the joint moves in linear or angular units"),
    position_key("JOINT_n", "MIN_LIMIT", "", "Lowest joint position; unset: the axis MIN_LIMIT"),
    position_key("JOINT_n", "MAX_LIMIT", "", "Highest joint position; unset: the axis MAX_LIMIT"),
    positive_key("JOINT_n", "MAX_VELOCITY", "1.0", "units/s", "Highest velocity of this joint"),
    positive_key("JOINT_n", "MAX_ACCELERATION", "1.0", "units/s^2",
                 "Highest acceleration of this joint"),
    positive_key("JOINT_n", "FERROR", "1", "units", "Following error limit at maximum velocity"),
    positive_key("JOINT_n", "MIN_FERROR", "", "units",
                 "Following error limit at standstill; unset: FERROR"),
    real_key("JOINT_n", "BACKLASH", "0", 0, kInf, "units",
             "Backlash compensated when the joint reverses"),
    position_key("JOINT_n", "HOME", "0", "Position the joint moves to after homing"),
    position_key("JOINT_n", "HOME_OFFSET", "0", "Position of the home switch or index pulse"),
    real_key("JOINT_n", "HOME_SEARCH_VEL", "0", -kInf, kInf, "units/s",
             "Velocity and direction of the home switch search; 0 = home where the joint is"),
    real_key("JOINT_n", "HOME_LATCH_VEL", "0", -kInf, kInf, "units/s",
             "Velocity and direction of the slow latch move off the switch"),
    real_key("JOINT_n", "HOME_FINAL_VEL", "-1", -kInf, kInf, "units/s",
             "Velocity of the move to HOME; negative: MAX_VELOCITY"),
    bool_key("JOINT_n", "HOME_USE_INDEX", "NO", "Latch on the encoder index pulse"),
    bool_key("JOINT_n", "HOME_INDEX_NO_ENCODER_RESET", "NO",
             "The encoder does not reset its count on the index pulse"),
    bool_key("JOINT_n", "HOME_IGNORE_LIMITS", "NO",
             "The home switch shares an input with a limit switch"),
    bool_key("JOINT_n", "HOME_IS_SHARED", "NO", "Several joints share one home switch input"),
    integer_key("JOINT_n", "HOME_SEQUENCE", "", -16, 16, "",
                "Step of \"home all\"; unset: not homed by it; negative: home with the same step "
                "synchronised (gantry)"),
    bool_key("JOINT_n", "VOLATILE_HOME", "0",
             "Forget the home position when the machine is turned off"),
    bool_key("JOINT_n", "LOCKING_INDEXER", "0",
             "Rotary indexer that must be unlocked before it moves"),
    integer_key("JOINT_n", "HOME_ABSOLUTE_ENCODER", "0", 0, 2, "",
                "Absolute encoder: 0 = no, 1 = home then move to HOME, 2 = home without moving"),
    real_key("JOINT_n", "SCALE", "0", -kInf, kInf, "steps/unit",
             "Steps or counts per unit for the driver; 0 = not given"),
    real_key("JOINT_n", "INPUT_SCALE", "0", -kInf, kInf, "counts/unit",
             "Encoder counts per unit (servo configs)"),
    real_key("JOINT_n", "OUTPUT_SCALE", "0", -kInf, kInf, "",
             "Drive output per unit/s (servo configs)"),
    choice_key("JOINT_n", "DRIVER", "sim", "sim|gpio|modbus",
               "Driver moving this joint: sim (simulated), gpio (step/dir), modbus"),

    text_key("GPIO", "CHIP", "",
             "GPIO chip of the step/dir lines: gpiochip0, /dev/gpiochip0, a label, or vcd:FILE to "
             "record the outputs to a value change dump instead of driving hardware"),
    line_key("GPIO", "ESTOP_LINE",
             "Line of the external estop input: LINE (offset or name), gpio:LINE, or gpio:!LINE "
             "for active low (= ESTOP_ACTIVE_LOW = 1); empty: none"),
    active_low_key("GPIO", "ESTOP_ACTIVE_LOW",
                   "The estop input is asserted at low level (normally closed to ground)"),
    line_key("GPIO", "PROBE_LINE",
             "Line of the probe input: LINE, gpio:LINE or gpio:!LINE (active low); empty: none. "
             "[CNCD] PROBE_INPUT takes a sim: probe too"),
    active_low_key("GPIO", "PROBE_ACTIVE_LOW", "The probe input is asserted at low level"),
    integer_key(
        "GPIO", "DEBOUNCE_NS", "0", 0, 1'000'000'000, "ns",
        "A switch input must hold a new level this long before it counts; 0 = one base period"),
    line_key("JOINT_n", "STEP_LINE",
             "gpio: line of the step output: LINE (offset or name) or gpio:LINE"),
    line_key("JOINT_n", "DIR_LINE",
             "gpio: line of the direction output, LINE or gpio:LINE (high = negative direction)"),
    line_key("JOINT_n", "ENABLE_LINE",
             "gpio: line of the drive enable output: LINE, gpio:LINE, or gpio:!LINE for "
             "ENABLE_ACTIVE_LOW = 1; empty: none"),
    active_low_key("JOINT_n", "ENABLE_ACTIVE_LOW",
                   "gpio: the enable output is low when the drive is enabled"),
    line_key("JOINT_n", "HOME_SWITCH_LINE",
             "gpio: line of the home switch input: LINE, gpio:LINE or gpio:!LINE (active low); "
             "empty: none"),
    active_low_key("JOINT_n", "HOME_SWITCH_ACTIVE_LOW",
                   "gpio: the home switch reads low when pressed"),
    line_key("JOINT_n", "MIN_LIMIT_LINE",
             "gpio: line of the minimum limit switch input: LINE, gpio:LINE or gpio:!LINE "
             "(active low); empty: none"),
    active_low_key("JOINT_n", "MIN_LIMIT_ACTIVE_LOW",
                   "gpio: the minimum limit switch reads low when tripped"),
    line_key("JOINT_n", "MAX_LIMIT_LINE",
             "gpio: line of the maximum limit switch input: LINE, gpio:LINE or gpio:!LINE "
             "(active low); empty: none"),
    active_low_key("JOINT_n", "MAX_LIMIT_ACTIVE_LOW",
                   "gpio: the maximum limit switch reads low when tripped"),
    position_key(
        "SIM", "PROBE_SURFACE_Z", "",
        "sim: the probe input trips where Z is at or below this (machine coordinates of the "
        "simulated motors); unset: the simulated probe never trips"),
    position_key("SIM", "PROBE_X_MIN", "", "sim: the probed block starts at this X; unset: no end"),
    position_key("SIM", "PROBE_X_MAX", "", "sim: the probed block ends at this X; unset: no end"),
    position_key("SIM", "PROBE_Y_MIN", "", "sim: the probed block starts at this Y; unset: no end"),
    position_key("SIM", "PROBE_Y_MAX", "", "sim: the probed block ends at this Y; unset: no end"),
    real_key("JOINT_n", "SIM_LAG", "0", 0, 10, "s",
             "sim: the simulated motor follows its command through a first-order lag of this time "
             "constant (to try the following-error limits); 0 = it is exactly where commanded"),
    step_timing_key("JOINT_n", "STEPLEN",
                    "gpio: shortest time the step line is high (rounded up to base periods)"),
    step_timing_key("JOINT_n", "STEPSPACE",
                    "gpio: shortest time the step line is low between steps"),
    step_timing_key("JOINT_n", "DIRSETUP",
                    "gpio: shortest time between a direction change and the next step"),
    step_timing_key("JOINT_n", "DIRHOLD",
                    "gpio: shortest time between the end of a step and a direction change"),
    real_key("JOINT_n", "STEPGEN_MAXVEL", "0", 0, kInf, "units/s",
             "gpio: velocity limit of the step generator; 0 = only the step timing limits it"),
    real_key("JOINT_n", "STEPGEN_MAXACCEL", "0", 0, kInf, "units/s^2",
             "gpio: acceleration limit of the step generator; 0 = unlimited"),
    integer_key("JOINT_n", "MODBUS", "", 0, 99, "",
                "modbus: number n of the [MODBUS_n] bus the drive is on"),
    integer_key("JOINT_n", "SLAVE", "", 1, 247, "", "modbus: unit identifier of the drive"),
    register_key("JOINT_n", "TARGET_REGISTER", "0",
                 "modbus: first holding register of the target position (counts)"),
    register_key("JOINT_n", "CONTROL_REGISTER", "2",
                 "modbus: holding register of the control word (bit 0 enable, bit 1 fault reset)"),
    register_key("JOINT_n", "POSITION_REGISTER", "0",
                 "modbus: first input register of the actual position (counts)"),
    register_key("JOINT_n", "STATUS_REGISTER", "2",
                 "modbus: input register of the status word (bit 0 ready, 1 enabled, 2 fault, "
                 "3 in position)"),
    choice_key("JOINT_n", "REGISTER_WIDTH", "32", "16|32",
               "modbus: positions are signed 16-bit (one register) or 32-bit (two registers)",
               "bits"),
    choice_key("JOINT_n", "WORD_ORDER", "HIGH_FIRST", "HIGH_FIRST|LOW_FIRST",
               "modbus: which register of a 32-bit position comes first"),
    choice_key("MODBUS_n", "TRANSPORT", "tcp", "tcp|rtu",
               "Modbus TCP (HOST, PORT) or RTU on a serial line (DEVICE, BAUD ...)"),
    text_key("MODBUS_n", "HOST", "", "tcp: address of the drive(s)"),
    integer_key("MODBUS_n", "PORT", "502", 1, 65535, "", "tcp: port"),
    text_key("MODBUS_n", "DEVICE", "",
             "rtu: serial device, e.g. "
             "/dev/ttyUSB0"),
    integer_key("MODBUS_n", "BAUD", "19200", 300, 4'000'000, "bit/s", "rtu: baud rate"),
    choice_key("MODBUS_n", "PARITY", "N", "N|E|O", "rtu: parity: none, even or odd"),
    integer_key("MODBUS_n", "DATA_BITS", "8", 5, 8, "", "rtu: data bits"),
    integer_key("MODBUS_n", "STOP_BITS", "1", 1, 2, "", "rtu: stop bits"),
    integer_key("MODBUS_n", "TIMEOUT_MS", "50", 1, 10'000, "ms", "Reply timeout of one request"),
    integer_key("MODBUS_n", "UPDATE_PERIOD_MS", "10", 1, 10'000, "ms",
                "How often every drive on the bus gets its setpoint and is read back"),
    integer_key("MODBUS_n", "RETRIES", "1", 0, 10, "",
                "Repeats of a failed request before the drive is faulted"),
};

constexpr auto kKeys = panel_keys::with_panel_keys(
    join_keys(join_keys(kMachineKeys, kins_keys::kKinsKeys), kTelemetryKeys));

bool matches_section(std::string_view pattern, std::string_view section) {
  if (pattern == "JOINT_n") return section.starts_with("JOINT_") && section.size() > 6;
  if (pattern == "MODBUS_n") {
    return section.starts_with("MODBUS_") && section.size() > 7 &&
           section.find_first_not_of("0123456789", 7) == std::string_view::npos;
  }
  if (pattern == "AXIS_L") return section.starts_with("AXIS_") && section.size() == 6;
  return pattern == section;
}

// "DIGITAL_OUTPUT_n" matches DIGITAL_OUTPUT_ and digits; "JOG_L_PLUS" and "MPG_AXIS_L" match
// any axis letter (upper case) for the L.
bool matches_key(std::string_view pattern, std::string_view key) {
  if (const std::size_t at = axis_placeholder(pattern); at != std::string_view::npos) {
    return key.size() == pattern.size() && key.substr(0, at) == pattern.substr(0, at) &&
           key.substr(at + 1) == pattern.substr(at + 1) &&
           std::string_view("XYZABCUVW").find(key[at]) != std::string_view::npos;
  }
  if (!pattern.ends_with("_n")) return pattern == key;
  const std::string_view prefix = pattern.substr(0, pattern.size() - 1);
  return key.size() > prefix.size() && key.starts_with(prefix) &&
         key.find_first_not_of("0123456789", prefix.size()) == std::string_view::npos;
}

}  // namespace

std::span<const KeySpec> key_table() {
  return kKeys;
}

const KeySpec* find_key_spec(std::string_view section, std::string_view key) {
  for (const auto& spec : kKeys) {
    if (matches_key(spec.key, key) && matches_section(spec.section, section)) return &spec;
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
