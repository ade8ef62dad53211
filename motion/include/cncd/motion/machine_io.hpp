// The servo loop's unit for everything but the axes: the spindle (direction, commanded speed
// with its override and limits, at-speed), coolant, the program's digital and analog outputs,
// and the actions queued with the path (IoAction) that set them or wait (at-speed, an input,
// a hold the task releases). Every method but the constructor is RT (servo thread); it knows
// nothing of drivers beyond the command and feedback records it fills and reads.
#pragma once

#include <cstdint>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/status.hpp"
#include "cncd/motion/sync_follower.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

// What the path executor asks when it reaches an action, and tells when a segment starts.
class ActionGate {
 public:
  virtual ~ActionGate() = default;
  // RT: does `action` (`first`: the first period it is asked) and says whether it is done;
  // false keeps the path waiting there, and it is asked again next period.
  CNCD_RT virtual bool run(const IoAction& action, bool first) noexcept = 0;
  // RT: a segment with outputs to set starts this period.
  CNCD_RT virtual void started(const SyncOutputs& sync) noexcept = 0;
  // RT: one period of `dt` s along a segment in step with the spindle (`first`: its first
  // period; `continues`: it follows a thread move that ran to its end, with nothing between,
  // and goes on along the same helix); `s` (in: where the path stood) and `v` are where the
  // path is and its speed. `stop` (an abort) brings it to rest. True once it is over.
  CNCD_RT virtual bool follow(const Segment& segment, bool first, bool continues,
                              double feed_override, bool stop, double dt, double& s,
                              double& v) noexcept = 0;
  // RT: the segment in step with the spindle is over or dropped.
  CNCD_RT virtual void sync_ended() noexcept = 0;
  // RT: how fast the spindle turns (rev/s, >= 0) for G95 feeds, as measured this period.
  CNCD_RT virtual double spindle_rps() const noexcept = 0;
};

class MachineIo final : public ActionGate {
 public:
  MachineIo(const config::MachineConfig& config, double period_s);

  CNCD_RT bool run(const IoAction& action, bool first) noexcept override;
  CNCD_RT void started(const SyncOutputs& sync) noexcept override;
  CNCD_RT bool follow(const Segment& segment, bool first, bool continues, double feed_override,
                      bool stop, double dt, double& s, double& v) noexcept override;
  CNCD_RT void sync_ended() noexcept override;
  CNCD_RT double spindle_rps() const noexcept override { return spindle_.actual_rpm / 60.0; }
  // The X axis's position (machine coordinates) this period: constant surface speed (G96)
  // sets the spindle's speed from it.
  CNCD_RT void track_x(double x) noexcept;
  CNCD_RT SyncStatus sync() const noexcept {
    SyncStatus out = sync_.status();
    out.done = syncs_done_;
    return out;
  }

  // The drivers' feedback of this period.
  CNCD_RT void feedback(const drivers::IoFeedback& in) noexcept;
  // What the drivers are told this period.
  CNCD_RT const drivers::IoCommand& command() const noexcept { return out_; }
  // Everything off at once: the spindle, coolant, outputs (estop, drives off, a fault, abort).
  CNCD_RT void stop_all() noexcept;
  // The wait the path is in ends (abort, flush): nothing is waited for any more.
  CNCD_RT void cancel_wait() noexcept;
  // The task's answer to a hold (tool change done, a user M code finished).
  CNCD_RT void release(std::uint32_t hold_id) noexcept;
  // The operator ends the wait of `kind` that began in cycle `since` (an answer meant for an
  // earlier wait is ignored): an M66 wait ends as on its timeout (#5399 = -1); an at-speed
  // wait goes on only while the spindle turns the way it is told.
  CNCD_RT void end_wait(WaitStatus::Kind kind, std::uint64_t since) noexcept;
  CNCD_RT void set_override(double ratio) noexcept;
  // Pause and resume with [SPINDLE_0] STOP_ON_PAUSE: the spindle stops once the path rests,
  // and restarts on resume; resume_ready() says when the path may go on (the spindle at
  // speed). resume_requested() is true when it restarts the spindle: the path waits.
  CNCD_RT void path_paused() noexcept;
  CNCD_RT bool resume_requested() noexcept;
  // The door opened and the path rests: the spindle stops and the coolant goes off; with
  // `restore` the next resume_requested() turns them on as they were, else they stay off.
  CNCD_RT void hold_at_rest(bool restore) noexcept;
  CNCD_RT bool resume_ready() noexcept;
  // An error that stops the path (not the machine): true once, with the event.
  CNCD_RT bool take_error(RtEvent& out) noexcept;
  // Spindle drive fault or stale answer this period: the machine faults.
  CNCD_RT bool drive_problem(RtEvent& out) const noexcept;

  CNCD_RT const SpindleStatus& spindle() const noexcept { return spindle_; }
  CNCD_RT const IoStatus& io() const noexcept { return io_; }
  CNCD_RT const WaitStatus& wait() const noexcept { return wait_; }
  CNCD_RT double input_result() const noexcept { return input_result_; }
  CNCD_RT std::uint64_t input_waits() const noexcept { return input_waits_; }
  // Called once a period after feedback(), with the cycle count.
  CNCD_RT void set_cycle(std::uint64_t cycle) noexcept { cycle_ = cycle; }

 private:
  // The commanded speed from the programmed one, the override and the limits.
  CNCD_RT void update_command() noexcept;
  CNCD_RT bool at_speed() const noexcept;
  // Turning the way it is told (not at rest, not reversing), whatever its speed.
  CNCD_RT bool turning_as_told() const noexcept;
  // What the drive is told: a change takes the next sequence number.
  CNCD_RT void command_spindle(bool enable, bool reverse, double rpm) noexcept;
  // This period's reading was taken after the latest spindle command reached the drive.
  CNCD_RT bool acknowledged() const noexcept;
  // Below this the spindle counts as at rest.
  CNCD_RT double stopped_rpm() const noexcept;
  CNCD_RT bool wait_at_speed(bool first) noexcept;
  // The spindle has not reached its speed within AT_SPEED_TIMEOUT: the error take_error() gives.
  CNCD_RT void not_at_speed() noexcept;
  CNCD_RT bool wait_input(const IoAction& action, bool first) noexcept;
  // machine_io_orient.cpp: M19. orient() starts (first) and waits for an orientation,
  // wait_orient() waits for one under way; step_orient() drives the spindle toward it each
  // period, from its position, and apply_orient() tells the drive.
  CNCD_RT bool orient(const IoAction& action, bool first) noexcept;
  CNCD_RT bool wait_orient(const IoAction& action, bool first) noexcept;
  CNCD_RT bool orient_waited(double timeout_s) noexcept;
  CNCD_RT void step_orient() noexcept;
  CNCD_RT void apply_orient() noexcept;
  CNCD_RT void end_orient() noexcept;
  // The spindle as the synchronized-motion follower sees it this period.
  CNCD_RT SyncFollower::Spindle sync_spindle() const noexcept;
  // A tap drives the spindle: its command replaces the program's.
  CNCD_RT void apply_tap() noexcept;
  // The drive told to turn at `rps` (signed), enabled whatever the speed.
  CNCD_RT void drive_at(double rps) noexcept;
  CNCD_RT double input_value(const IoAction& action) const noexcept;

  const config::SpindleConfig& config_;
  double period_s_;
  bool ideal_;  // no [SPINDLE_0]: at any speed at once, and drives nothing
  drivers::IoCommand out_{};
  drivers::IoFeedback in_{};
  SpindleStatus spindle_{};
  IoStatus io_{};
  WaitStatus wait_{};
  std::uint64_t cycle_ = 0;
  std::uint64_t waited_ = 0;  // periods the current wait has been asked
  bool released_ = false;
  std::uint32_t released_id_ = 0;
  bool wait_ended_ = false;  // end_wait() for the wait under way
  bool last_input_ = false;  // M66 edges: the input in the previous period
  double input_result_ = 0;
  std::uint64_t input_waits_ = 0;
  bool has_error_ = false;
  RtEvent error_{};
  bool resuming_ = false;  // STOP_ON_PAUSE: restarted, waiting for at-speed before going on
  // hold_at_rest(true) turned the coolant off: what resume_requested() turns on again.
  bool coolant_held_ = false;
  bool held_flood_ = false;
  bool held_mist_ = false;
  std::uint64_t resume_waited_ = 0;
  // Synchronized motion: the follower, whether it drives the spindle (a tap), and the
  // spindle's position last period (its signed speed) or, for the ideal spindle, where its
  // command has taken it.
  SyncFollower sync_;
  double x_ = 0;  // the X axis, for G96
  bool tapping_ = false;
  double tap_rps_ = 0;  // what the tap drives the spindle at, signed
  bool has_last_revolutions_ = false;
  double last_revolutions_ = 0;
  std::int64_t last_position_ns_ = 0;  // when the spindle stood at last_revolutions_ (0: no time)
  // The time between the spindle's last two positions (a late servo period, or one run straight
  // after it, by the spindle driver's clock), or one period.
  double elapsed_s_ = 0;
  double spindle_rps_ = 0;  // measured, signed
  std::uint64_t syncs_done_ = 0;
  // The way the spindle was last told to turn (1, -1; 0: never), and whether a reversal is
  // under way: told the other way, and not yet seen at rest or turning the new way.
  int turning_ = 0;
  bool reversing_ = false;
  // M19: orienting (spindle_.orient != 0); the spindle first comes to rest, then its target (in
  // revolutions, where it stood plus the turn to the angle) is fixed.
  bool orient_placed_ = false;
  int orient_mode_ = 0;
  double orient_target_ = 0;
  double orient_rps_ = 0;  // what the orientation drives the spindle at, signed
};

}  // namespace cncd::motion
