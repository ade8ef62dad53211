// What the task reports: the status snapshot (status.get and the status updates) and the
// coordinate systems (offsets.get), as plain values in machine units. The server turns them
// into the control protocol's JSON (status_json.hpp); docs/protocol.md says what each means.
#pragma once

#include <cstddef>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cncd/config/enum_name.hpp"
#include "cncd/interp/canon.hpp"
#include "cncd/interp/tool_entry.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::daemon {

enum class ExecState { idle, running, paused };
enum class Mode { manual, automatic, mdi };

// "G54" .. "G59.3" for coordinate system 1..9.
std::string coord_system_name(int system);
// "estop", "off" or "on", as status and errors name the machine's state.
using config::enum_name;

const char* machine_state_name(motion::MachineState state);
const char* exec_state_name(ExecState state);

struct JointReport {
  bool homed = false;
  bool fault = false;
  motion::JointStatus io;  // switches and drive, as the servo thread read them last
  double commanded = 0;    // joint position, joint units (a corexy motor: X + Y or X - Y)
  double actual = 0;
};

struct ProgramReport {
  std::string path;     // the open program, "" when none
  std::string opening;  // the program being checked for program.open, "" when none
  int line = 0;
  std::uint64_t total_lines = 0;
  // "linuxcnc" | "numeryx": the open program's dialect, the machine's when none is open.
  std::string dialect;
  double progress = 0;  // 0 .. 1
  bool stepping = false;
  std::uint64_t moves = 0;
  double elapsed_s = 0;
  double motion_s = 0;
  std::optional<double> estimated_s;  // unknown: see remaining_reason
  std::optional<double> remaining_s;
  std::string remaining_reason;
  std::string result;  // "done" | "aborted" | "error" | "" (never ran)
  std::string error;
};

struct SpindleReport {
  int direction = 0;  // 1 cw, -1 ccw, 0 stopped
  double speed = 0;   // rpm, with the override (commanded_rpm, or what it would be when stopped)
  double programmed_speed = 0;
  double override_ratio = 1.0;
  bool override_enabled = true;
  bool enabled = false;
  double commanded_rpm = 0;  // what the drive is told: 0 when stopped, within the limits
  double actual_rpm = 0;
  bool at_speed = true;
  std::optional<double> position;  // revolutions, with an encoder (or the sim spindle)
  // G96: the spindle's speed follows X; programmed_speed is then the surface speed (m/min in
  // G21, ft/min in G20) and css_max_rpm its D. Unset in G97.
  std::optional<double> css_max_rpm;
  // M19: "orienting" to orient_angle (degrees), or "oriented" and held there; "" otherwise.
  std::string orient;
  double orient_angle = 0;
};

// The machine's outputs and inputs.
struct IoReport {
  std::uint32_t douts = 0;
  std::vector<double> aouts;
  std::uint32_t dins = 0;
  std::vector<double> ains;
};

// What a running program waits for ("" kind: nothing).
struct WaitReport {
  // "tool_change" | "spindle_at_speed" | "input" | "user_m" | "spindle_orient" | ""
  std::string kind;
  int tool = 0;  // tool_change
  std::string message;
  double since_s = 0;  // how long it has waited
};

// G38.x: the probe input and the last probing move's outcome.
struct ProbeReport {
  bool contact = false;  // the probe input now
  bool probing = false;  // a probing move is under way
  // The last probing move of this daemon: whether it tripped (lost contact, away) and where
  // (machine coordinates; where it ended when it did not trip). Unset before the first.
  std::optional<bool> last_tripped;
  motion::AxisPose last_position{};
};

// Motion in step with the spindle (G33, G33.1, rigid G84/G74) under way, if any.
struct SyncReport {
  std::string mode;     // "thread" | "tap" | "" (none)
  std::string phase;    // SyncStatus::Phase in words
  double per_rev = 0;   // units per revolution (machine units)
  double progress = 0;  // revolutions from the move's start
};

// A feed hold that takes effect only once the move in step with the spindle under way has
// ended: a thread or a tap is never left midway.
struct PauseWaitReport {
  std::string kind;  // "thread_end" | "tap_end" | "" (none)
  int line = 0;      // the move's line
  std::string message;
};
// What a feed hold waits for while `sync` is under way on `line` (none without one).
PauseWaitReport pause_wait_report(const motion::SyncStatus& sync, int line);

struct ToolReport {
  int number = 0;     // in the spindle, 0 = none
  int prepared = -1;  // -1 = none
  interp::Pose length_offset{};
  std::optional<interp::ToolEntry> entry;  // the table's entry for the tool in the spindle
};

// The offsets in force.
struct ActiveOffsets {
  int coord_system = 1;  // 1..9 = G54..G59.3
  interp::Pose g5x{};
  double rotation_deg = 0;
  interp::Pose g92{};
};

// The panel ([PANEL]) as status.get shows it.
struct PanelReport {
  std::vector<std::pair<std::string, bool>> inputs;  // each wired input by its INI key
  std::vector<std::pair<std::string, bool>> lights;  // each lamp by its INI key
  int mpg_axis = -1;                                 // axis index, -1: none selected
  double mpg_step = 0;
  std::int64_t mpg_counts = 0;
  bool mpg_jogging = false;
  bool door = false;  // open
  bool single_block = false;
  bool optional_stop = true;  // M1 stops
  bool block_delete = false;  // '/' lines are skipped
};

// Tool centre point control on a machine that has it (a table-rotary kinematics).
struct TcpReport {
  // M428 in force in the interpreter: the next move it reads (a program's, an MDI block's) is
  // under TCP.
  bool programmed = false;
  // The path segment the servo thread runs now, or the last one it ran, is under TCP.
  bool motion = false;
  // The tool tip in the part's frame (what X Y Z mean under TCP; the rotaries as they stand),
  // from the commanded and the actual joints: machine units.
  motion::AxisPose tip_commanded{};
  motion::AxisPose tip_actual{};
};

// Who has manual motion now (one hand on the machine): the panel's MPG or a jog button, or
// the client that jogs, by the name its events carry.
struct ManualHolder {
  std::string by;      // "the panel's MPG", "the panel's JOG_X_PLUS button", a client
  bool panel = false;  // the panel (at the machine) rather than a client
  int axis = -1;       // the jog target it moves (an axis, or kMaxAxes + a joint), -1: several
};

struct TaskStatus {
  motion::MachineState machine = motion::MachineState::estop;
  ExecState exec = ExecState::idle;
  Mode mode = Mode::manual;
  motion::MotionState motion = motion::MotionState::idle;
  std::vector<JointReport> joints;  // the configured joints
  std::string fault;                // latched fault, "" when none
  std::optional<ManualHolder> manual_holder;
  motion::AxisPose commanded{};  // machine coordinates
  motion::AxisPose actual{};
  // "clean", "unclean" or "none": where the joints started (Task::load_files).
  std::string position_restored;
  motion::AxisPose work_commanded{};  // work coordinates; X a diameter under G7
  motion::AxisPose work_actual{};
  bool diameter_mode = false;  // G7 in force
  double velocity = 0;
  double distance_to_go = 0;
  motion::AxisPose axes_to_go{};  // per axis, of the segment being executed
  double feed_override = 1.0;
  double rapid_override = 1.0;
  ProgramReport program;
  SpindleReport spindle;
  bool mist = false;
  bool flood = false;
  IoReport io;
  WaitReport wait;
  ProbeReport probe;
  SyncReport sync;
  PauseWaitReport pause_wait;  // while a feed hold waits for a synchronized move's end
  ToolReport tool;
  ActiveOffsets offsets;
  std::vector<std::string> gcodes;  // active, in modal-group order: "G1", "G17" ...
  std::vector<std::string> mcodes;
  double feed_rate = 0;  // program units per minute
  motion::RtStats rt;
  std::optional<PanelReport> panel;  // none without [PANEL]
  std::optional<TcpReport> tcp;      // none on a machine without TCP
};

// offsets.get: every coordinate system's origin and the G92 offset.
struct CoordSystemReport {
  int index = 1;  // 1..9 = G54..G59.3
  interp::Pose origin{};
  double rotation_deg = 0;
};

struct OffsetsReport {
  int active = 1;
  std::array<CoordSystemReport, 9> systems{};
  interp::Pose g92{};
};

}  // namespace cncd::daemon
