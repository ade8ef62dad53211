// The servo loop's cycle: commands in, trajectory advanced, joints written to the drivers,
// feedback checked, status published. cycle() is the whole real-time part; the thread and the
// clock live in MotionController, so tests run it in virtual time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/motion/rt_stats.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/seqlock.hpp"
#include "cncd/motion/spsc_ring.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

struct Command {
  enum class Kind : std::uint8_t { estop, reset_estop, on, off, home, abort, pause, resume };
  Kind kind = Kind::estop;
  std::uint32_t joint_mask = 0;
};

// Something the servo thread tells the non-RT side (which logs it).
struct Event {
  enum class Level : std::uint8_t { info, warning, fault };
  Level level = Level::info;
  char text[120] = {};
};

// One joint's place in a driver: the servo loop hands each driver its joints' commands as a
// contiguous block, in the order of `joints`.
struct DriverBinding {
  drivers::Driver* driver = nullptr;
  std::vector<int> joints;
};

class ServoLoop {
 public:
  using SegmentRing = SpscRing<Segment, 1024>;
  using CommandRing = SpscRing<Command, 64>;
  using EventRing = SpscRing<Event, 64>;

  ServoLoop(const config::MachineConfig& config, std::vector<DriverBinding> drivers);

  // RT: one servo period. `wake_error_ns` is how late this cycle woke (for the statistics).
  void cycle(std::int64_t wake_error_ns) noexcept;

  SegmentRing& segments() noexcept { return segments_; }
  CommandRing& commands() noexcept { return commands_; }
  EventRing& events() noexcept { return events_; }
  Status status() const noexcept { return published_.load(); }
  void set_rt_flags(bool realtime, bool memory_locked) noexcept;

 private:
  struct JointMotion {  // homing move of one joint
    bool active = false;
    double start = 0;
    double target = 0;
    double traveled = 0;  // distance covered from start
    double velocity = 0;
    double max_velocity = 0;
    double max_acceleration = 0;
  };
  void apply(const Command& command) noexcept;
  void stop_now(MachineState next, const char* reason) noexcept;
  void flush_queue() noexcept;
  void advance_path(double dt) noexcept;
  void advance_homing(double dt) noexcept;
  void start_home_sequence() noexcept;
  void latch_fault(const char* reason) noexcept;
  void post(Event::Level level, const char* text) noexcept;
  void sync_axes_from_joints() noexcept;
  void publish() noexcept;

  const config::MachineConfig& config_;
  std::vector<DriverBinding> drivers_;
  double period_s_;
  int joint_count_;
  std::array<int, kJoints> joint_axis_{};  // axis index a joint follows

  SegmentRing segments_;
  CommandRing commands_;
  EventRing events_;
  Seqlock<Status> published_;

  Status status_{};
  Segment active_{};
  bool has_active_ = false;
  double path_s_ = 0;
  double path_v_ = 0;
  double dwell_elapsed_s_ = 0;
  bool pause_requested_ = false;
  bool abort_requested_ = false;
  AxisPose axis_pose_{};
  JointArray joint_cmd_{};
  JointArray last_written_{};
  std::array<JointMotion, kJoints> homing_{};
  std::uint32_t home_pending_ = 0;  // joints still to home
  int home_sequence_ = -1;          // sequence being homed, -1 = none
  std::array<drivers::JointCommand, kJoints> commands_out_{};
  std::array<drivers::JointFeedback, kJoints> feedback_{};
  RtHistogram histogram_;
};

}  // namespace cncd::motion
