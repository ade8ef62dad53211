// Typed, validated machine configuration built from a LinuxCNC-style INI file.
// A MachineConfig is immutable once loaded; every thread may read it.
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cncd/config/panel_config.hpp"
#include "cncd/config/signal_address.hpp"

namespace cncd::config {

class IniFile;

// Axis letters in LinuxCNC's canonical order; an axis index is a position in this string.
inline constexpr std::string_view kAxisLetters = "XYZABCUVW";
inline constexpr int kMaxAxes = 9;
inline constexpr int kMaxJoints = 16;
static_assert(kPanelAxes == kMaxAxes);

// Index of an axis letter (either case) in kAxisLetters, or -1.
int axis_index(char letter);

enum class LinearUnits { mm, inch };
enum class AngularUnits { degree, radian, grad };
enum class JointType { linear, angular };
// How programs are read ([RS274NGC] DIALECT): LinuxCNC's RS274NGC or the Numeryx drilling
// dialect (the interpreter's Dialect; config depends on no other part of cncd).
enum class Dialect { linuxcnc, numeryx };

struct AxisConfig {
  bool present = false;      // letter appears in [TRAJ] COORDINATES
  double min_limit = -1e99;  // machine units (mm, inch or degrees)
  double max_limit = 1e99;
  double max_velocity = 0;      // units/s
  double max_acceleration = 0;  // units/s^2
  double max_jerk = 0;          // units/s^3, 0 = unlimited
  SourceRef source;
};

// The geometry of a table-rotary machine ([KINS] keys named as LinuxCNC's xyzac-trt-kins and
// xyzbc-trt-kins pins; docs/kinematics.md). Machine units.
struct TableRotaryConfig {
  // Where the C axis (the rotary table's) crosses, relative to the machine's zero.
  double x_rot_point = 0, y_rot_point = 0, z_rot_point = 0;
  // From the C axis to the tilting axis: Y and Z for A (xyzac), X and Z for B (xyzbc).
  double x_offset = 0, y_offset = 0, z_offset = 0;
  // From the tool tip the table turns about up to the controlled point, along the spindle.
  double tool_offset = 0;
  // [TRAJ] TCP_TOLERANCE: how far the tool tip may leave a programmed line under TCP.
  double tcp_tolerance = 0.005;
};

struct JointConfig {
  JointType type = JointType::linear;
  // The axis this joint drives (trivkins joint map); '\0' for an extra joint that no axis
  // drives (LinuxCNC's num_extrajoints, or joints beyond the trivkins coordinates= letters)
  // and for corexykins' joints 0 and 1, the X + Y and X - Y motors.
  char axis = 'X';
  double min_limit = -1e99;  // joint units
  double max_limit = 1e99;
  double max_velocity = 0;      // units/s
  double max_acceleration = 0;  // units/s^2
  double ferror = 1;            // following error limit at max velocity
  double min_ferror = 0.25;     // following error limit at standstill (INI default: FERROR)
  double backlash = 0;
  // Homing, LinuxCNC semantics: HOME_SEARCH_VEL = 0 homes immediately at the current position.
  double home = 0;
  double home_offset = 0;
  double home_search_vel = 0;
  double home_latch_vel = 0;
  double home_final_vel = -1;  // < 0: move to HOME at max velocity
  int home_sequence = -1;      // < 0: not part of a "home all"
  // HOME_SEQUENCE was written negative: LinuxCNC's synchronised homing, all joints with the
  // same |HOME_SEQUENCE| (home_sequence holds that absolute value) home and finish together.
  bool home_sequence_sync = false;
  bool home_index_no_encoder_reset = false;
  bool locking_indexer = false;
  bool home_use_index = false;
  bool home_ignore_limits = false;
  bool home_is_shared = false;
  bool home_absolute_encoder = false;  // HOME_ABSOLUTE_ENCODER 1 or 2
  bool volatile_home = false;
  // Scaling: steps or counts per unit. SCALE is the stepgen/driver key, INPUT/OUTPUT_SCALE the
  // encoder/DAC keys of servo configs; 0 = not given.
  double scale = 0;
  double input_scale = 0;
  double output_scale = 0;
  std::string driver = "sim";  // DRIVER: sim | gpio | modbus
  SourceRef source;            // the [JOINT_n] header
};

// Digital and analog signals a program can reach: M62-M65 / M66 digital, M66-M68 analog.
inline constexpr int kMaxDigitalIo = 32;
inline constexpr int kMaxAnalogIo = 16;

enum class SpindleDriver { none, sim, gpio, modbus };

// [SPINDLE_0]. A machine with no such section has an ideal spindle: it is at any commanded
// speed at once and drives nothing (LinuxCNC's spindle with nothing wired to it).
struct SpindleConfig {
  bool present = false;  // the section is in the file
  // DRIVER = none: the machine has no spindle (a program that starts one is refused).
  SpindleDriver driver = SpindleDriver::sim;
  // LinuxCNC 2.9 keys, rpm. The reverse ones are positive numbers, as LinuxCNC writes them
  // (a negative one is read as its magnitude, as LinuxCNC does); MAX_REVERSE_VELOCITY
  // defaults to MAX_FORWARD_VELOCITY, MIN_REVERSE_VELOCITY to MIN_FORWARD_VELOCITY (to 0 when
  // MAX_REVERSE_VELOCITY = 0 forbids reverse).
  double max_forward_velocity = 1e99;
  double min_forward_velocity = 0;
  double max_reverse_velocity = 1e99;
  double min_reverse_velocity = 0;
  double increment = 100;            // rpm, the step of a user interface's faster/slower
  double acceleration = 0;           // rpm/s the sim and PWM spindles ramp at; 0 = at once
  double at_speed_tolerance = 0.05;  // fraction of the commanded speed
  double at_speed_timeout_s = 10;    // past it without reaching speed, the program stops
  bool stop_on_pause = false;        // STOP_ON_PAUSE: a pause stops the spindle, resume restarts it
  // gpio
  SignalAddress enable;
  SignalAddress direction;  // high for reverse (M4)
  SignalAddress pwm;
  double pwm_frequency = 1000;  // Hz
  double pwm_min_duty = 0;      // fraction; duty = min + (1 - min) * rpm / max_forward_velocity
  SignalAddress encoder_a;
  SignalAddress encoder_b;
  SignalAddress encoder_index;
  int encoder_ppr = 0;  // pulses per revolution (quadrature: 4 counts each), 0 = no encoder
  // modbus: a VFD on [MODBUS_n], generic register profile (every register a key)
  int modbus = -1;  // n of [MODBUS_n]
  int slave = 1;
  double speed_scale = 1;         // register value = rpm x SPEED_SCALE
  int command_register = 0;       // holding: COMMAND_STOP / _FORWARD / _REVERSE
  int speed_register = 1;         // holding: commanded speed
  int actual_speed_register = 0;  // actual speed, in actual_speed_table (-1 = none)
  int status_register = 1;        // status bits, in status_table (-1 = none)
  // Where the drive keeps its read-only registers: input registers (function 4) or holding
  // registers (function 3), ACTUAL_SPEED_TABLE / STATUS_TABLE = ir | hr.
  SignalAddress::Table actual_speed_table = SignalAddress::Table::input;
  SignalAddress::Table status_table = SignalAddress::Table::input;
  int command_stop = 0;
  int command_forward = 1;
  int command_reverse = 2;
  int running_bit = 0;  // of the status register; -1 = none
  int at_speed_bit = 1;
  int fault_bit = 2;
  // The shaft's position, for spindle-synchronized motion: a counter of POSITION_WIDTH bits
  // (two registers for 32, WORD_ORDER), in POSITION_TABLE, POSITION_SCALE counts a revolution
  // (negative: it counts down turning forward). -1 = the drive reports no position.
  int position_register = -1;
  SignalAddress::Table position_table = SignalAddress::Table::input;
  int position_width = 32;
  bool position_high_first = true;
  double position_scale = 0;
  SourceRef source;  // the [SPINDLE_0] header
};

// What M6 does besides waiting for the operator ([EMCIO]).
struct ToolChangeConfig {
  bool has_position = false;                    // TOOL_CHANGE_POSITION given
  std::array<double, kMaxAxes> position{};      // machine coordinates, indexed by axis_index()
  std::array<bool, kMaxAxes> position_given{};  // the axes TOOL_CHANGE_POSITION names
  bool quill_up = false;                        // TOOL_CHANGE_QUILL_UP: Z to machine zero first
  bool with_spindle_on = false;  // TOOL_CHANGE_WITH_SPINDLE_ON: the spindle keeps turning
};

// Coolant and the program's digital and analog signals ([CNCD] keys).
struct IoConfig {
  SignalAddress flood;                                       // FLOOD_OUTPUT, M8
  SignalAddress mist;                                        // MIST_OUTPUT, M7
  std::array<SignalAddress, kMaxDigitalIo> digital_outputs;  // DIGITAL_OUTPUT_n
  std::array<SignalAddress, kMaxAnalogIo> analog_outputs;    // ANALOG_OUTPUT_n
  std::array<SignalAddress, kMaxDigitalIo> digital_inputs;   // DIGITAL_INPUT_n
  std::array<SignalAddress, kMaxAnalogIo> analog_inputs;     // ANALOG_INPUT_n
  // PROBE_INPUT: the probe G38.x stops on (gpio or sim; [GPIO] PROBE_LINE is the same as a
  // gpio address here).
  SignalAddress probe_input;
  // User M codes M100-M199: executables looked for in these directories, in order: the first
  // program directory ([DISPLAY] PROGRAM_PREFIX, which LinuxCNC searches first), then
  // [RS274NGC] USER_M_PATH; absolute. Run for at most user_m_timeout_s.
  std::vector<std::filesystem::path> user_m_path;
  double user_m_timeout_s = 60;
};

struct CncdConfig {
  std::string socket_path = "/run/cncd/cncd.sock";
  std::string read_group;     // empty: only root and the control group may connect
  std::string control_group;  // empty: only root may command
  // Control socket connections: in all, per user (not root or cncd's own), and the part of
  // the total kept for control peers.
  int max_connections = 1000;
  int max_connections_per_user = 128;
  int control_reserve = 8;
  int rt_priority = 80;  // SCHED_FIFO priority of the servo thread
  int rt_cpu = -1;       // CPU to pin the servo thread to, -1 = any
  // Run from line: Z rises to this height (machine coordinates) before X and Y move over the
  // line's start; none: [AXIS_Z] MAX_LIMIT.
  std::optional<double> run_from_line_safe_z;
  std::string log_level = "info";  // trace|debug|info|warn|error|critical|off
  // Where the parameter, tool and position files named by relative paths live: --state-dir,
  // else [CNCD] STATE_DIR, else $STATE_DIRECTORY (systemd), else $XDG_STATE_HOME/cncd/<INI
  // name> ($HOME/.local/state/cncd/<INI name>). Empty only when none of them is known.
  std::filesystem::path state_dir;
  std::string state_dir_origin;  // which of those chose it, for messages
  // [CNCD] PROBE_DIR, absolute: where (PROBEOPEN name) files go; a relative key is taken from
  // the state directory, and no key is its probe/ subdirectory. Empty only without either.
  std::filesystem::path probe_dir;
};

// [WEB]: cncd-web, the browser dashboard and WebSocket proxy (docs/web.md).
// [TELEMETRY]: what the daemon counts and records for the shop's systems, and what
// cncd-telemetry serves them (cncd reads the section too, and checks it).
struct TelemetryConfig {
  // Which program end counts a part in the job history: M30 only, M2 or M30, or none.
  enum class PartCount { m30, m2, off };
  PartCount part_count = PartCount::m30;
  // The machine's name towards the shop: letters, digits, '-', '_' and '.'; default [EMC]
  // MACHINE with every other character as '_', else the INI's file name without .ini.
  std::string machine_id;
  // Prometheus /metrics: address and port; port 0 = not served.
  std::string metrics_address = "127.0.0.1";
  int metrics_port = 9877;
  // The MTConnect SHDR adapter: address and port; port 0 = not served.
  std::string shdr_address = "127.0.0.1";
  int shdr_port = 7878;
  // MQTT: the broker (no host: none), its credentials and TLS CA file, the protocol (5 or
  // 311), the topics' prefix (default cncd/<machine id>), positions a second (0: none) and the
  // events kept for the broker while it is away.
  std::string mqtt_host;
  int mqtt_port = 1883;
  std::string mqtt_username;
  std::string mqtt_password;
  std::filesystem::path mqtt_tls_ca;
  int mqtt_protocol = 5;
  std::string topic_prefix;
  double position_hz = 5;
  int event_queue = 10000;
  // The machine's own dashboard, published in the state for the fleet page; "" = none.
  std::string dashboard_url;
};

struct WebConfig {
  std::string listen = "127.0.0.1";  // address to bind; any other than loopback is explicit
  int port = 8080;
  // Where uploads go and programs are listed from; absolute, one of program_dirs. Default:
  // the first of program_dirs.
  std::filesystem::path program_dir;
  std::int64_t max_upload_bytes = 64LL << 20;  // MAX_UPLOAD_MB
  // Users, roles, password hashes and API key hashes; absolute. Default: web-users in the
  // state directory.
  std::filesystem::path users_file;
  // TLS: both or neither; absolute.
  std::filesystem::path tls_cert;
  std::filesystem::path tls_key;
  // Origins besides the page's own that a browser's WebSocket may come from (e.g. the address
  // nginx serves the page at), "scheme://host[:port]".
  std::vector<std::string> allowed_origins;
  int session_hours = 12;         // a login's lifetime
  int max_clients = 64;           // WebSocket connections at once
  double jog_heartbeat_s = 0.25;  // a continuous jog stops this long after its last heartbeat
};

struct MachineConfig {
  std::filesystem::path path;  // the INI file as given
  std::string machine_name;    // [EMC] MACHINE
  // [EMCMOT]
  std::int64_t servo_period_ns = 1'000'000;
  std::int64_t base_period_ns = 0;  // 0 = no base thread
  // [TASK]
  double task_cycle_time_s = 0.001;
  // [RS274NGC]; paths are resolved relative to the INI file's directory, except the state
  // files (parameter_file, tool_table, position_file): a relative one lives in the state
  // directory, and its *_seed is the file of that name beside the INI, copied there when the
  // state directory has none yet. An absolute one is used where it is, without a seed.
  std::filesystem::path parameter_file;
  std::filesystem::path parameter_file_seed;
  std::string startup_code;
  std::vector<std::filesystem::path> subroutine_path;
  // DIALECT: how programs are read unless their first line names another dialect; MDI is
  // always read in it.
  Dialect dialect = Dialect::linuxcnc;
  // NUMERYX_CLEARANCE, machine units (R1 = R + clearance in Numeryx cycles); unset: the
  // interpreter's default (1 mm in a G21 program, 0.04 in in a G20 one).
  std::optional<double> numeryx_clearance;
  // RIGID_TAPPING: G84/G74 are rigid (in step with the spindle) instead of floating.
  bool rigid_tapping = false;
  // [EMCIO]
  std::filesystem::path tool_table;
  std::filesystem::path tool_table_seed;
  // [TRAJ]
  // [TRAJ] COORDINATES without blanks, upper case: the axes the machine has, a letter repeated
  // for every joint of a gantry ("XYYZ"). Which joint drives which axis is JointConfig::axis.
  std::string coordinates = "XYZ";
  LinearUnits linear_units = LinearUnits::mm;
  AngularUnits angular_units = AngularUnits::degree;
  double default_linear_velocity = 0;  // units/s
  double max_linear_velocity = 0;      // units/s
  double default_linear_acceleration = 0;
  double max_linear_acceleration = 0;
  double max_linear_jerk = 0;  // units/s^3, 0 = unlimited
  // S-curve profiles: path motion changes its acceleration by at most max_linear_jerk per
  // second ([TRAJ] PLANNER_TYPE, MAX_LINEAR_JERK).
  bool scurve = false;
  std::filesystem::path position_file;
  std::filesystem::path position_file_seed;
  bool no_force_homing = false;
  // [KINS]
  // Module name only: "trivkins", "corexykins", "xyzac-trt-kins" or "xyzbc-trt-kins".
  std::string kinematics = "trivkins";
  std::string kinematics_args;     // the rest, e.g. "coordinates=XYYZ kinstype=both"
  TableRotaryConfig table_rotary;  // xyzac-trt-kins and xyzbc-trt-kins
  int joint_count = 0;
  int extra_joints = 0;  // [EMCMOT] EMCMOT = motmod num_extrajoints=N
  // [DISPLAY]
  double max_feed_override = 1.0;  // 1.0 = 100 %
  double min_spindle_override = 1.0;
  double max_spindle_override = 1.0;
  // The directories program.open opens programs from (and from below): [DISPLAY]
  // PROGRAM_PREFIX, then [CNCD] PROGRAM_DIRS, absolute; neither given: the INI's own
  // directory. Symlinks are resolved when a program is opened, not here.
  std::vector<std::filesystem::path> program_dirs;
  std::array<AxisConfig, kMaxAxes> axes;  // indexed by axis_index()
  std::vector<JointConfig> joints;        // joint_count entries
  CncdConfig cncd;
  TelemetryConfig telemetry;
  WebConfig web;
  SpindleConfig spindle;  // [SPINDLE_0]
  ToolChangeConfig tool_change;
  IoConfig io;
  PanelConfig panel;  // [PANEL]
  // Every key of the file with its source, for lookups of keys this struct does not type
  // and to list unused keys. Null when built by hand.
  std::shared_ptr<const IniFile> ini;

  const AxisConfig& axis(char letter) const {
    return axes[static_cast<std::size_t>(axis_index(letter))];
  }
  // Millimetres per machine linear unit (1 or 25.4).
  double mm_per_unit() const { return linear_units == LinearUnits::inch ? 25.4 : 1.0; }
};

// One problem found while reading or validating; printed as "FILE:LINE: [SECTION] KEY: message".
struct Problem {
  std::string file;
  int line = 0;         // 0 = no line (e.g. missing file)
  std::string section;  // without brackets, may be empty
  std::string key;      // may be empty
  std::string message;
  std::string to_string() const;
};

struct LoadResult {
  std::optional<MachineConfig> config;  // set only when problems is empty
  std::vector<Problem> problems;        // every problem found, in file order
  // Things LinuxCNC tolerates but a machinist should hear about (missing include, defaults
  // used for unspecified velocities, ignored lines); never a reason to refuse the file.
  std::vector<Problem> warnings;
  bool ok() const { return config.has_value(); }
};

struct LoadOptions {
  // --state-dir: the state directory, before [CNCD] STATE_DIR; empty = not given.
  std::filesystem::path state_dir;
  // Looks up an environment variable ($STATE_DIRECTORY, $XDG_STATE_HOME, $HOME).
  const char* (*getenv)(const char* name) = [](const char* name) -> const
      char* { return std::getenv(name); };
};

// Reads, validates and types an INI file. Never throws on bad input; collects all problems.
LoadResult load_machine_config(const std::filesystem::path& ini_path,
                               const LoadOptions& options = {});

// For the programs that only read a machine's INI (cncd-web, cncd-telemetry): its
// configuration, or nullopt after writing each problem on a line of `err` and then
// "PROGRAM: N problems in INI".
std::optional<MachineConfig> load_or_report(const std::filesystem::path& ini_path,
                                            std::string_view program, std::ostream& err);

// The copy of a state file to read: `file` when it exists, else `seed` when that exists,
// else `file` (which then does not exist: the defaults apply). cncd-check reads this way
// without writing; the daemon copies the seed into place first (daemon/src/state_files.cpp).
std::filesystem::path state_file_to_read(const std::filesystem::path& file,
                                         const std::filesystem::path& seed);

// A readable multi-line summary (axes, joints, limits, units, period, drivers) for
// `cncd --check-config`.
std::string describe(const MachineConfig& config);

// Exit status for an invalid configuration (sysexits EX_CONFIG).
inline constexpr int kExitConfig = 78;

}  // namespace cncd::config
