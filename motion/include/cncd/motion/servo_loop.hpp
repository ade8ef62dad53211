// The servo loop's cycle: commands in, trajectory advanced, joints written to the drivers,
// feedback checked, status published. cycle() is the whole real-time part; the thread and the
// clock live in MotionController, so tests run it in virtual time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/motion/command_history.hpp"
#include "cncd/motion/homing.hpp"
#include "cncd/motion/jog.hpp"
#include "cncd/motion/rt_stats.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/seqlock.hpp"
#include "cncd/motion/spsc_ring.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

struct Command {
  enum class Kind : std::uint8_t {
    estop,
    reset_estop,
    on,
    off,
    home,
    abort,
    pause,
    resume,
    jog_start,
    jog_increment,
    jog_stop,
    feed_override,  // velocity = the new ratio
    rapid_override  // velocity = the new ratio
  };
  Kind kind = Kind::estop;
  std::uint32_t joint_mask = 0;
  int axis = 0;         // jogs: axis index
  double velocity = 0;  // jog_start: units/s, signed; jog_increment: speed
  double distance = 0;  // jog_increment: units, signed
};

// Something the servo thread tells the non-RT side (which logs it).
struct Event {
  enum class Level : std::uint8_t { info, warning, fault };
  Level level = Level::info;
  char text[240] = {};  // room for a fault_reason with the driver's own words
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

  // Non-RT. `config` must outlive the loop; the drivers are configured and enabled by the
  // caller. Starts in estop.
  ServoLoop(const config::MachineConfig& config, std::vector<DriverBinding> drivers);

  // RT: one servo period. `wake_error_ns` is how late this cycle woke (for the statistics).
  void cycle(std::int64_t wake_error_ns) noexcept;

  // Producer: the planner (task thread). Consumer: the servo thread.
  SegmentRing& segments() noexcept { return segments_; }
  // Producer: the task thread. Consumer: the servo thread.
  CommandRing& commands() noexcept { return commands_; }
  // Producer: the servo thread. Consumer: the task thread.
  EventRing& events() noexcept { return events_; }
  // Any thread.
  Status status() const noexcept { return published_.load(); }
  // Before the first cycle, or on the servo thread.
  void set_rt_flags(bool realtime, bool memory_locked) noexcept;
  // Before the first cycle: the joints start at these positions (still unhomed) wherever the
  // drives report them, as with LinuxCNC's [TRAJ] POSITION_FILE; the motor offsets take up
  // the difference on the first cycle.
  void set_start_positions(const JointArray& joints) noexcept;

 private:
  void apply(const Command& command) noexcept;
  void start_homing(std::uint32_t mask) noexcept;
  void stop_now(MachineState next, const char* reason) noexcept;
  void flush_queue() noexcept;
  bool advance_path(double dt) noexcept;                      // true: a move ran this period
  bool starts_here(const Segment& segment) noexcept;          // false: fault latched
  bool joints_on_their_axes() noexcept;                       // false: fault latched
  double speed_limit(const Segment& segment) const noexcept;  // with overrides and holds
  // Path motion under way or waiting, in the look-ahead window or in the ring.
  bool path_pending() const noexcept { return window_count_ > 0 || segments_.size() > 0; }
  Segment& window_at(std::uint64_t seq) noexcept {
    return window_[static_cast<std::size_t>(seq % kWindow)];
  }
  // Takes segments from the ring while the window holds less than the path needs to stop
  // from its fastest speed, and brings the exit speeds up to date, within this period's work
  // budget.
  void fill_window() noexcept;
  // Continues the backward pass over the exit speeds for up to pass_budget_ steps.
  void run_pass() noexcept;
  // The overrides or a hold changed: the override-dependent exit speeds are all recomputed.
  void soft_limits_changed() noexcept;
  void finish_front() noexcept;          // the window's first segment is done
  double window_floor_accel() noexcept;  // the smallest acceleration limit in the window
  // S-curve profiles (servo_scurve.cpp): one period of path motion whose acceleration changes
  // by at most jerk_ per second, through as many segments as it covers. Spends all of `dt`.
  void scurve_step(double& dt) noexcept;
  // The speed limits ahead of the path's position into limits_, as far as the path, `ds`
  // further on at speed `v` and acceleration `a`, could need to slow down for them.
  void gather_limits(double ds, double v, double a) noexcept;
  // Whether a step from `v_before`, `a_before` to speed `v` and acceleration `a`, `ds` further on,
  // keeps every limit gathered (the hard ones only when `soft` is false): those it passes, and
  // those ahead it can still slow down for; with `speeds_only`, the speeds alone and not the
  // coming segments' acceleration limits.
  bool keeps_limits(double v_before, double a_before, double v, double a, double ds, bool soft,
                    bool speeds_only = false) const noexcept;
  // Whether a deceleration `a` at speed `v`, `ds` further on, can ease off to every coming
  // segment's own acceleration limit before reaching it.
  bool eases_in_time(double v, double a, double ds) const noexcept;
  void advance_homing() noexcept;
  void apply_jog(const Command& command) noexcept;  // servo_jog.cpp
  void advance_jog() noexcept;
  bool axis_homed(int axis) const noexcept;
  void read_drivers() noexcept;
  void check_joints() noexcept;  // servo_feedback.cpp, like read_drivers and write_drivers
  // Joint `k`'s command of `cycle` (motor coordinates) as feedback names it: 0 or a cycle not
  // written yet is the latest one written, one that fell out of the history its oldest.
  drivers::JointCommand answered_command(std::size_t k, std::uint64_t cycle) const noexcept;
  void write_drivers() noexcept;
  // RT: a joint whose set-point is not a number keeps its last command and the machine
  // faults ("non-finite set-point on joint N"): a drive never sees a NaN or an infinity.
  void guard_set_points() noexcept;
  void update_stats(std::int64_t wake_error_ns) noexcept;
  void latch_fault(const char* reason) noexcept;
  void post(Event::Level level, const char* text) noexcept;
  void sync_axes_from_joints() noexcept;
  void adopt_start_positions() noexcept;
  void publish() noexcept;

  const config::MachineConfig& config_;
  std::vector<DriverBinding> drivers_;
  double period_s_;
  int joint_count_;
  std::array<int, kJoints> joint_axis_{};                 // axis index a joint follows, -1 = none
  std::array<drivers::Driver*, kJoints> joint_driver_{};  // the driver a joint belongs to

  SegmentRing segments_;
  CommandRing commands_;
  EventRing events_;
  Seqlock<Status> published_;

  Status status_{};
  bool drives_enabled_ = false;  // the last commands sent to the drives enabled them
  // Look-ahead window: the segments taken from the ring, oldest first; the first is being
  // executed once has_active_. Segment sequence number n lives in window_[n % kWindow];
  // head_seq_ is the first's. exit_hard_ is the fastest speed at a segment's end from which
  // the path can still stop within the window under the axis limits alone, exit_soft_ the
  // same with the feed, the overrides and holds: the window's last segment always ends at
  // rest. Both are kept by an incremental backward pass.
  static constexpr int kWindow = 2048;
  static constexpr int kPassBudget = 4096;  // pass steps and ring pops per period
  static constexpr int kMaxPulls = 256;     // ring pops per period (each copies a segment)
  bool has_active_ = false;
  std::array<Segment, kWindow> window_{};
  std::array<double, kWindow> exit_hard_{};
  std::array<double, kWindow> exit_soft_{};
  std::uint64_t head_seq_ = 0;
  int window_count_ = 0;
  double window_length_ = 0;  // path length of the window's segments
  double stop_length_ = 0;    // longest stopping distance of the window's segments
  // The window's segments (dwells aside) whose acceleration limit is below that of every later
  // one, oldest first, in a ring indexed by the two counters: the first has the window's
  // smallest limit (S-curve profiles: how far ahead a limit can bind).
  std::array<std::uint64_t, kWindow> floor_seq_{};
  std::uint64_t floor_first_ = 0;
  std::uint64_t floor_end_ = 0;
  bool pass_active_ = false;
  std::uint64_t pass_seq_ = 0;    // next segment whose exit speeds the pass recomputes
  std::uint64_t pass_floor_ = 0;  // the pass goes at least this far back
  int pass_budget_ = 0;
  int pulls_left_ = 0;
  double path_s_ = 0;
  double path_v_ = 0;
  double path_a_ = 0;  // S-curve profiles only
  // S-curve profiles: the path's jerk limit (0: trapezoidal profiles) and the limits ahead.
  double jerk_ = 0;
  static constexpr double kMinRampPeriods = 20;
  struct SpeedLimit {
    double distance;  // from the path's position
    double soft;      // with the feed, the overrides and holds
    double hard;      // of the axes alone
    double accel;     // smallest path acceleration limit of the segments up to there
    double entry;     // the acceleration limit of the segment that starts there
    bool soft_on;     // whether the soft (hard) speed binds: no nearer limit is as low
    bool hard_on;
  };
  static constexpr int kMaxLimits = 1024;
  std::array<SpeedLimit, kMaxLimits> limits_{};
  int limit_count_ = 0;
  double cap_soft_ = 0, cap_hard_ = 0;  // the active segment's own speed limits
  double dwell_elapsed_s_ = 0;
  bool pause_requested_ = false;
  bool abort_requested_ = false;
  AxisPose axis_pose_{};
  JointIo joints_{};
  Homing homing_;
  Jog jog_;
  // Servo cycles counted from 1 (drivers::JointCommand::cycle), and every joint's motor
  // commands of the last cycles, for feedback that answers an older one.
  std::uint64_t cycle_ = 0;
  CommandHistory history_;
  JointArray last_motor_cmd_{};  // what the drivers were told last period (motor coordinates)
  std::array<drivers::JointCommand, kJoints> commands_out_{};
  std::array<drivers::JointFeedback, kJoints> feedback_{};  // motor coordinates
  RtHistogram histogram_;
  JointArray start_positions_{};
  bool has_start_positions_ = false;
};

}  // namespace cncd::motion
