// The status snapshot the servo thread publishes every period (trivially copyable).
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/panel_config.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

enum class MachineState : std::uint8_t { estop, off, on };
enum class MotionState : std::uint8_t { idle, moving, pausing, paused, stopping, homing, jogging };

// The edges (us) of the wake-up error histogram the status carries, as Prometheus buckets.
inline constexpr std::array<std::int32_t, 14> kWakeEdgesUs = {
    5, 10, 25, 50, 100, 250, 500, 1000, 2500, 5000, 10000, 25000, 50000, 100000};

struct RtStats {
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;  // periods whose wake-up came later than one period
  std::int64_t wake_error_p50_ns = 0;
  std::int64_t wake_error_p99_ns = 0;
  std::int64_t wake_error_p999_ns = 0;
  std::int64_t wake_error_max_ns = 0;
  // Taken with the percentiles: wake-ups that came less than kWakeEdgesUs[i] late, and the
  // count and sum (ns) of all wake-ups then.
  std::array<std::uint64_t, kWakeEdgesUs.size()> wake_error_below{};
  std::uint64_t wake_error_count = 0;
  std::uint64_t wake_error_sum_ns = 0;
  // Field-bus (Modbus) requests that failed since the drivers started: timeouts, exceptions,
  // lost links and failed connects.
  std::uint64_t modbus_errors = 0;
  bool realtime = false;       // SCHED_FIFO granted
  bool memory_locked = false;  // mlockall succeeded
};

// One joint's switches and drive as the servo thread saw them in the last period.
struct JointStatus {
  bool min_limit = false;  // limit switch inputs as read this period
  bool max_limit = false;
  bool home_switch = false;  // home switch input as read this period
  bool enabled = false;      // the servo thread commands the drive enabled
  bool drive_fault = false;  // the driver reports a drive fault this period
  bool stale = false;        // the driver has no fresh feedback within its deadline
  // Homed, and the commanded position stands at the joint's soft limit ([JOINT_n] MIN_LIMIT /
  // MAX_LIMIT, within a micron or so).
  bool at_min_soft_limit = false;
  bool at_max_soft_limit = false;
  char driver[12] = {};  // the driver's name ("sim", "gpio", "modbus"), "" when none
};

// The spindle as the servo thread commands it and its driver reports it.
struct SpindleStatus {
  bool present = true;           // the machine has a spindle ([SPINDLE_0] DRIVER is not none)
  bool enabled = false;          // commanded to turn
  std::int8_t direction = 0;     // 1 M3, -1 M4, 0 stopped
  double programmed_rpm = 0;     // S as the program set it
  double commanded_rpm = 0;      // with the override, within the limits (0 when stopped)
  double actual_rpm = 0;         // as the driver reports it (the command, with no driver)
  bool at_speed = false;         // turning at the commanded speed (or stopped, when stopped)
  double override_ratio = 1.0;   // spindle override
  bool override_enabled = true;  // M51 P0 / M49 turn it off
  bool has_position = false;     // revolutions comes from an encoder (or the sim spindle)
  double revolutions = 0;
  bool paused_off = false;  // stopped by a pause (STOP_ON_PAUSE) or the door; resume restarts it
  // M19: turning to orient_deg (1), or holding there (2); 0: not oriented.
  std::int8_t orient = 0;
  double orient_deg = 0;
  // G96 (IoAction::css_*): programmed_rpm is then the surface speed; 0 = G97.
  double css_numerator = 0;
  double css_max_rpm = 0;
  double css_x_origin = 0;
};

// The machine's outputs and inputs.
struct IoStatus {
  bool flood = false;
  bool mist = false;
  std::uint32_t douts = 0;  // bit n: digital output n
  std::array<double, kMaxAnalogIo> aouts{};
  std::uint32_t dins = 0;  // bit n: digital input n
  std::array<double, kMaxAnalogIo> ains{};
};

// What the path waits for at an action (IoAction): none while it moves.
struct WaitStatus {
  enum class Kind : std::uint8_t {
    none,
    spindle_at_speed,
    input,
    tool_change,
    user_m,
    spindle_orient
  };
  Kind kind = Kind::none;
  std::uint32_t hold_id = 0;  // tool_change and user_m: what IoAction::hold_id the task answers
  std::int16_t index = 0;     // input: its index
  bool digital = true;        // input: digital or analog
  std::uint64_t since = 0;    // servo cycle the wait began in
};

// G38.x: the probe input and the last probing move's outcome.
struct ProbeStatus {
  bool contact = false;    // the probe input now (any driver's)
  bool armed = false;      // a probing move is under way
  std::uint64_t done = 0;  // probing moves ended (tripped, or not) since the start
  bool tripped = false;    // the last one tripped (or lost contact, away)
  AxisPose position{};     // where it tripped (machine coordinates), else where it ended
};

// Motion in step with the spindle (G33, G33.1, rigid G84/G74): none while there is none.
struct SyncStatus {
  enum class Phase : std::uint8_t {
    none,
    spindle_stopping,  // tap: the spindle comes to rest before the tap starts
    tapping_in,        // tap: the spindle and the axis go into the hole
    tapping_out,       // tap: reversed, back out to where the tap started
    index,             // thread: waiting for the spindle's next whole revolution
    following,         // thread: the path follows the spindle
    stopping,          // an abort: the spindle (tap) or the path (thread) comes to rest
  };
  SpindleSync mode = SpindleSync::none;
  Phase phase = Phase::none;
  double per_rev = 0;      // units per revolution
  double progress = 0;     // revolutions from the start along the segment (into the hole)
  std::uint64_t done = 0;  // synchronized segments ended since the start
};

// The panel ([PANEL]) as the servo thread sees it: what the task acts on.
struct PanelStatus {
  std::uint64_t inputs = 0;  // debounced levels, bit (1 << config::PanelInput)
  // Debounced presses (rising edges) of each input since the start: the task compares them
  // with those it has acted on, so no press between two of its cycles is lost.
  std::array<std::uint32_t, config::kPanelInputs> presses{};
  // The counters (config::PanelCounter) unwrapped, from 0 at the start.
  std::array<std::int64_t, config::kPanelCounters> counts{};
  std::array<double, config::kPanelAnalogs> analog{};  // as read
  std::int8_t mpg_axis = -1;  // the axis the selector picks, -1: none (or more than one)
  double mpg_step = 0;        // machine units a detent moves, by the step selector
  bool mpg_jogging = false;   // the MPG moves an axis now
  std::uint32_t lights = 0;   // bit (1 << config::PanelLight), as told to the drivers
};

// What the servo thread publishes every period.
struct ServoStatus {
  std::uint64_t sequence = 0;  // servo cycle count at publication
  MachineState machine = MachineState::estop;
  MotionState motion = MotionState::idle;
  int joint_count = 0;
  std::array<bool, kJoints> homed{};
  std::array<bool, kJoints> joint_fault{};
  std::array<JointStatus, kJoints> joints{};
  AxisPose commanded{};  // machine units, machine coordinates
  AxisPose actual{};
  JointArray joint_commanded{};
  JointArray joint_actual{};
  // Tool centre point control (Kinematics::has_tcp(), a table-rotary machine): the tool tip
  // in the part's frame for the commanded and the actual position (Kinematics::tcp_forward()
  // of the axes above, whatever the TCP state), and whether the path segment under way, or
  // the last one run, was planned under TCP (M428). All false or zero without it.
  bool has_tcp = false;
  bool tcp = false;
  AxisPose tip_commanded{};
  AxisPose tip_actual{};
  double velocity = 0;              // units/s along the path
  double distance_to_go = 0;        // path distance left in the segment being executed
  AxisPose axes_to_go{};            // that segment's end less the commanded position, per axis
  double feed_override = 1.0;       // applied to feed moves, 0 .. [DISPLAY] MAX_FEED_OVERRIDE
  double rapid_override = 1.0;      // applied to traverses, 0 .. 1
  std::int32_t line = 0;            // source line of the segment being executed
  std::uint32_t queued = 0;         // segments waiting in the queue (including the active one)
  std::uint64_t segments_done = 0;  // segments completed (or dropped by an abort) since start
  std::uint64_t moves_done = 0;     // programmed moves completed (or dropped) since start
  std::uint64_t actions_done = 0;   // actions (Move::Kind::action) completed or dropped
  RtEvent fault;                    // latched fault, code none when none
  SpindleStatus spindle;
  IoStatus io;
  WaitStatus wait;
  // M66: the last wait's result (#5399) and how many waits have ended since the start.
  double input_result = 0;
  std::uint64_t input_waits = 0;
  // Errors that stopped the path but not the machine (a spindle that did not reach its speed
  // in time): the last one, and how many there have been since the start.
  RtEvent path_error;
  std::uint64_t path_errors = 0;
  ProbeStatus probe;
  SyncStatus sync;
  PanelStatus panel;
  RtStats rt;
};

// The servo thread's snapshot as its readers see it: the latched fault also in words, put
// there by the reader.
struct Status : ServoStatus {
  char fault_reason[kEventTextSize] = {};  // "" when none
};

}  // namespace cncd::motion
