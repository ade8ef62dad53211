// The servo loop's cycle: commands in, trajectory advanced, joints written to the drivers,
// feedback checked, status published. cycle() is the whole real-time part; the thread and the
// clock live in MotionController, so tests run it in virtual time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/drivers/seqlock.hpp"
#include "cncd/motion/feedback_checks.hpp"
#include "cncd/motion/homing.hpp"
#include "cncd/motion/jog.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/machine_io.hpp"
#include "cncd/motion/panel.hpp"
#include "cncd/motion/path_executor.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/rt_stats.hpp"
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
    feed_override,     // velocity = the new ratio
    rapid_override,    // velocity = the new ratio
    spindle_override,  // velocity = the new ratio
    release,           // id: the hold the task answers (tool change done, user M code ended)
    end_wait,          // id: the WaitStatus::Kind the operator ends, since: that wait's `since`
    panel_lights,      // id: bits (1 << config::PanelLight) to light; red also lights in estop
    // The door opened: once the path rests the spindle and coolant stop; id 1: the next resume
    // turns them on again (and the path waits for the spindle's speed), id 0: for good (M5 M9).
    io_hold
  };
  Kind kind = Kind::estop;
  std::uint32_t joint_mask = 0;
  int axis = 0;             // jogs: axis index, or joint index when `joint`
  double velocity = 0;      // jog_start: units/s, signed; jog_increment: speed
  double distance = 0;      // jog_increment: units, signed
  std::uint32_t id = 0;     // release, end_wait, panel_lights, io_hold
  std::uint64_t since = 0;  // end_wait
  bool joint = false;       // jogs: of a joint in joint mode
};

// Something the servo thread tells the non-RT side (which logs it), as that side reads it.
struct Event {
  using Level = EventLevel;
  Level level = Level::info;
  RtEvent record;
  char text[kEventTextSize] = {};  // the record in words
};

// The consumer's end of the servo thread's events: each record is put in words as it is
// popped, on the consumer's thread.
class EventReader {
 public:
  using Ring = SpscRing<RtEvent, 64>;
  explicit EventReader(Ring& ring) noexcept : ring_(ring) {}
  // Consumer thread. False when empty.
  bool pop(Event& out) noexcept;

 private:
  Ring& ring_;
};

// One joint's place in a driver: the servo loop hands each driver its joints' commands as a
// contiguous block, in the order of `joints`.
struct DriverBinding {
  drivers::Driver* driver = nullptr;
  std::vector<int> joints;
};

// The coordinator of the servo period: the machine's state (estop, off, on), the mode (path,
// homing, jogging), faults and the order of the period (cycle()). The work is done by its
// units, each usable and tested on its own: PathExecutor (look-ahead and profiles), Homing,
// Jog and FeedbackChecks.
class ServoLoop {
 public:
  using SegmentRing = PathExecutor::SegmentRing;
  using CommandRing = SpscRing<Command, 64>;
  using EventRing = EventReader::Ring;

  // Non-RT. `config` must outlive the loop; the drivers are configured and enabled by the
  // caller. Starts in estop.
  ServoLoop(const config::MachineConfig& config, std::vector<DriverBinding> drivers);

  // RT: one servo period. `wake_error_ns` is how late this cycle woke (for the statistics).
  CNCD_RT void cycle(std::int64_t wake_error_ns) noexcept;

  // Producer: the planner (task thread). Consumer: the servo thread.
  SegmentRing& segments() noexcept { return path_.segments(); }
  // Producer: the task thread. Consumer: the servo thread.
  CommandRing& commands() noexcept { return commands_; }
  // Producer: the servo thread. Consumer: the task thread.
  EventReader events() noexcept { return EventReader(events_); }
  // Any thread but the servo thread (the fault is put in words here).
  Status status() const noexcept;
  // Before the first cycle, or on the servo thread.
  void set_rt_flags(bool realtime, bool memory_locked) noexcept;
  // Before the first cycle: the joints start at these positions (still unhomed) wherever the
  // drives report them, as with LinuxCNC's [TRAJ] POSITION_FILE; the motor offsets take up
  // the difference on the first cycle.
  void set_start_positions(const JointArray& joints) noexcept;

 private:
  CNCD_RT void apply(const Command& command) noexcept;
  CNCD_RT void start_homing(std::uint32_t mask) noexcept;
  CNCD_RT void stop_now(MachineState next) noexcept;
  // Reset and machine on: from `from` to `to` with the faults forgotten; false (nothing
  // changes) when the machine is not in `from`.
  CNCD_RT bool clear_into(MachineState from, MachineState to) noexcept;
  // One period of path motion: the executor's progress into the status, its fault latched,
  // the joints moved with their axes.
  CNCD_RT void advance_path() noexcept;
  // The path's actions and outputs (MachineIo) after the path's period: an error of theirs
  // stops the path, a pause may stop the spindle, a resume waits for it.
  CNCD_RT void advance_io() noexcept;
  // G38.x (servo_probe.cpp): before the path advances, a probing move that trips (or loses
  // contact) latches where the machine is and stops; after it, a probing move that has just
  // started is armed (or refused when the probe is already as it should end), and one that has
  // ended is reported.
  CNCD_RT void watch_probe() noexcept;
  CNCD_RT void follow_probe() noexcept;
  CNCD_RT void probe_error(RtEvent::Code code) noexcept;
  // An abort or a stop ends a probing move without an outcome.
  CNCD_RT void disarm_probe() noexcept;
  // The first joint whose command stands apart from where the axes put it, or -1.
  CNCD_RT int joint_apart() const noexcept;
  CNCD_RT void advance_homing() noexcept;
  CNCD_RT void apply_jog(const Command& command) noexcept;  // servo_jog.cpp
  // Starts a joint-mode jog, or says why not.
  CNCD_RT const char* joint_jog_refusal(const Command& command) noexcept;
  // Whether a joint of `axis` stands apart from where the axis puts it (after joint jogs of
  // one of a gantry's joints): the axis may not jog then.
  CNCD_RT bool axis_joints_apart(int axis) const noexcept;
  CNCD_RT void advance_jog() noexcept;
  CNCD_RT bool axis_homed(int axis) const noexcept;
  // The panel (servo_panel.cpp): inputs read into status_.panel, then the MPG's counts turned
  // into a jog of the selected axis, or dropped when it may not move.
  CNCD_RT void advance_panel() noexcept;
  CNCD_RT void mpg_position(int axis, std::int64_t counts) noexcept;
  CNCD_RT void mpg_velocity(int axis, std::int64_t counts) noexcept;
  // Stops the MPG's jog (if any) and forgets its counts and target.
  CNCD_RT void mpg_release() noexcept;
  // The MPG's jog ends when its axis comes to rest (status_.panel.mpg_jogging).
  CNCD_RT void settle_mpg() noexcept;
  // The lights the drivers are told: the task's, and red in estop or with a fault.
  CNCD_RT std::uint32_t panel_lights() const noexcept;
  CNCD_RT void read_drivers() noexcept;
  // Feedback judged by checks_; the first joint that fails latches the fault.
  CNCD_RT void check_joints() noexcept;  // servo_feedback.cpp, like read_drivers and write_drivers
  // A spindle drive that faults or stops answering faults the machine.
  CNCD_RT void check_spindle() noexcept;
  CNCD_RT void write_drivers() noexcept;
  // RT: a joint whose set-point is not a number keeps its last command and the machine
  // faults (RtEvent::Code::set_point_not_finite): a drive never sees a NaN or an infinity.
  CNCD_RT void guard_set_points() noexcept;
  CNCD_RT void update_stats(std::int64_t wake_error_ns) noexcept;
  // The first fault latched stays in the status until the machine is reset or turned on.
  CNCD_RT void latch_fault(RtEvent fault) noexcept;
  CNCD_RT void latch_fault(RtEvent::Code code, int joint = -1) noexcept;
  CNCD_RT void post(const RtEvent& event) noexcept;
  CNCD_RT void warn(RtEvent::Code code, const char* words = nullptr) noexcept;
  CNCD_RT void sync_axes_from_joints() noexcept;
  CNCD_RT void adopt_start_positions() noexcept;
  CNCD_RT void publish() noexcept;

  const config::MachineConfig& config_;
  std::vector<DriverBinding> drivers_;
  double period_s_;
  int joint_count_;
  std::unique_ptr<const Kinematics> kins_;  // joints to axes and back

  CommandRing commands_;
  EventRing events_;
  drivers::Seqlock<ServoStatus> published_;

  ServoStatus status_{};
  bool drives_enabled_ = false;  // the last commands sent to the drives enabled them
  AxisPose axis_pose_{};
  JointIo joints_{};
  MachineIo io_;
  PathExecutor path_;
  Homing homing_;
  Jog jog_;
  Jog joint_jog_;  // joint mode: single joints, the axes following them
  // Servo cycles counted from 1 (drivers::JointCommand::cycle).
  std::uint64_t cycle_ = 0;
  Panel panel_;
  drivers::PanelFeedback panel_in_{};  // this period's readings
  std::uint32_t lights_asked_ = 0;     // by the task (Command::Kind::panel_lights)
  // The MPG's jog: the axis it moves (-1: none), its counts as last seen, counts short of a
  // detent; position mode: the target is base + detents x step; velocity mode: the counts of
  // the last window of periods, a ring.
  struct Mpg {
    static constexpr int kWindowMax = 256;
    int axis = -1;
    int moving = -1;  // the axis whose jog the MPG started, until it comes to rest
    std::int64_t seen = 0;
    std::int64_t carry = 0;
    double base = 0;
    std::int64_t detents = 0;
    double step = 0;
    bool drop = false;  // an abort or a client's stop: forget the target this period
    int window = 1;     // periods in the velocity window
    int at = 0;
    std::int64_t window_sum = 0;
    int quiet = 0;  // periods since the last count
    double velocity = 0;
    std::array<std::int32_t, kWindowMax> ring{};
  } mpg_;
  FeedbackChecks checks_;
  JointArray last_motor_cmd_{};  // what the drivers were told last period (motor coordinates)
  std::array<drivers::JointCommand, kJoints> commands_out_{};
  std::array<drivers::JointFeedback, kJoints> feedback_{};  // motor coordinates
  RtHistogram histogram_;
  JointArray start_positions_{};
  bool has_start_positions_ = false;
  drivers::Driver* spindle_driver_ = nullptr;  // the driver that reports the spindle
  bool resume_pending_ = false;                // a resume waits for the spindle (STOP_ON_PAUSE)
  bool io_hold_pending_ = false;               // io_hold: the spindle stops once the path rests
  bool io_hold_restore_ = false;               // ... and the next resume restores it
  bool probe_input_ = false;                   // read this period
  ProbeMode probe_mode_ = ProbeMode::none;     // of the armed probing move
  bool probe_tripped_ = false;
  AxisPose probe_position_{};
};

}  // namespace cncd::motion
