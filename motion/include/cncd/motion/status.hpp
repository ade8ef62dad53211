// The status snapshot the servo thread publishes every period (trivially copyable).
#pragma once

#include <array>
#include <cstdint>

#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

enum class MachineState : std::uint8_t { estop, off, on };
enum class MotionState : std::uint8_t { idle, moving, pausing, paused, stopping, homing, jogging };

struct RtStats {
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;  // periods whose wake-up came later than one period
  std::int64_t wake_error_p50_ns = 0;
  std::int64_t wake_error_p99_ns = 0;
  std::int64_t wake_error_p999_ns = 0;
  std::int64_t wake_error_max_ns = 0;
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
  double velocity = 0;              // units/s along the path
  double distance_to_go = 0;        // path distance left in the segment being executed
  double feed_override = 1.0;       // applied to feed moves, 0 .. [DISPLAY] MAX_FEED_OVERRIDE
  double rapid_override = 1.0;      // applied to traverses, 0 .. 1
  std::int32_t line = 0;            // source line of the segment being executed
  std::uint32_t queued = 0;         // segments waiting in the queue (including the active one)
  std::uint64_t segments_done = 0;  // segments completed (or dropped by an abort) since start
  std::uint64_t moves_done = 0;     // programmed moves completed (or dropped) since start
  RtEvent fault;                    // latched fault, code none when none
  RtStats rt;
};

// The servo thread's snapshot as its readers see it: the latched fault also in words, put
// there by the reader.
struct Status : ServoStatus {
  char fault_reason[kEventTextSize] = {};  // "" when none
};

}  // namespace cncd::motion
