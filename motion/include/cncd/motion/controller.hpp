// MotionController: owns the planner and the servo thread, and runs the drivers it is given.
//
// Threads: the task thread calls every public method; the servo thread is internal. Status is
// read lock-free (seqlock) from any thread.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/motion/move_queue.hpp"
#include "cncd/motion/servo_loop.hpp"
#include "cncd/motion/status.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class MotionController final : public MoveQueue {
 public:
  explicit MotionController(const config::MachineConfig& config);
  ~MotionController() override;
  MotionController(const MotionController&) = delete;
  MotionController& operator=(const MotionController&) = delete;

  // Takes the machine's configured drivers (drivers::make_drivers, or a test's own), enables
  // them and starts the servo thread at [EMCMOT] SERVO_PERIOD, SCHED_FIFO priority
  // [CNCD] RT_PRIORITY, pinned to [CNCD] RT_CPU when given, memory locked. Returns "" or an
  // error (a joint no driver drives). What the OS refuses (SCHED_FIFO, the CPU, mlockall) does
  // not stop it: start_warnings() then says what, once, for the caller to log. Calling start()
  // again after stop() starts afresh (estop, unhomed) with the drivers given then.
  std::string start(std::vector<drivers::DriverInstance> drivers);
  // Joint positions (machine units, joint order) the next start() begins at instead of where
  // the drives stand, unhomed: LinuxCNC's [TRAJ] POSITION_FILE. Call before start().
  void set_start_positions(const std::vector<double>& joints);
  // Stops the servo thread (joins it) and disables the drives. Idempotent.
  void stop();

  enum class EnqueueResult { queued, full, refused };
  // Queues one move (planned here, on the caller's thread). `full`: the segment queue has no
  // room, call again later. `refused`: the move cannot be made (machine not on, outside the
  // soft limits, zero feed ...); enqueue_error() says why.
  // The planner may hold the newest move back until the next one (or flush()) shows how the
  // two join; Status::moves_done counts the moves carried out.
  EnqueueResult enqueue(const Move& move);
  // Releases the move held back for look-ahead, to end at rest: call before anything that
  // must happen at rest or in order, and when no more moves come for now. `full`: part of it
  // did not fit in the segment queue, call again later.
  EnqueueResult flush();
  // Forgets the move held back (a run that starts afresh or ended early). abort() does too.
  void discard();
  const std::string& enqueue_error() const;
  // MoveQueue: enqueue(), flush() and enqueue_error() as a program's runner calls them.
  Push push_move(const Move& move) override;
  void end_path() override { flush(); }
  std::string refusal() const override { return enqueue_error(); }
  // Free slots in the segment queue.
  std::size_t queue_space() const;

  // Priority commands: they bypass queued motion, and each returns once the servo thread has
  // applied it (a period or two; at most 1 s), so a status() read afterwards reflects it.
  void estop();                         // latch estop: stop within one period, drives disabled
  void reset_estop();                   // leave estop (machine stays off)
  void machine_on();                    // enable drives (needs estop reset)
  void machine_off();                   // stop at once, disable drives
  void home(std::uint32_t joint_mask);  // home these joints (all-ones = all in HOME_SEQUENCE)
  void abort();                         // controlled stop, flush queued motion, abort homing
  void pause();                         // feed hold: controlled stop on the path
  void resume();
  // Overrides, applied by the servo thread from its next period on, also to the move under
  // way: feed moves run at min(programmed feed x feed override, what the axes allow),
  // traverses at their axis-limited speed x rapid override. The ratio is clamped to
  // [0, [DISPLAY] MAX_FEED_OVERRIDE] (feed) or [0, 1] (rapid); 0 stops on the path, within the
  // acceleration limits, until the override is raised again. A non-finite ratio is ignored.
  // Status::feed_override and Status::rapid_override show the ratios in force.
  void set_feed_override(double ratio);
  void set_rapid_override(double ratio);
  // The spindle override (ratio, 1.0 = 100 %) scales the commanded spindle speed at once,
  // within [SPINDLE_0]'s speed limits, unless the program turned it off (M48/M49, M51).
  void set_spindle_override(double ratio);
  // Ends the hold the path waits in (Status::wait, an IoAction::Kind::hold) when its id is
  // `hold_id`: the tool is changed, the user M code has finished.
  void release_hold(std::uint32_t hold_id);
  // Ends the wait Status::wait shows (`kind`, begun in servo cycle `since`), when it is still
  // that one: an M66 wait as on its timeout, an at-speed wait while the spindle turns.
  void end_wait(WaitStatus::Kind kind, std::uint64_t since);
  // The panel's lamps ([PANEL] LIGHT_*, LAMP_*): bits (1 << config::PanelLight) to light.
  void set_panel_lights(std::uint32_t bits);
  // The door is open: once the path rests the spindle stops and the coolant goes off; with
  // `restore` the next resume() turns them on as they were and the path waits for the
  // spindle's speed, else they stay off.
  void hold_io_at_rest(bool restore);

  // Jogs of one axis (config::axis_index), run by the servo thread within the axis's
  // MAX_VELOCITY (speeds above it are capped) and MAX_ACCELERATION; on a homed axis up to its
  // soft limit. `axis` kJointJogBase + n jogs joint n alone (joint mode) within its [JOINT_n]
  // limits, refused on a homed joint that moves with an axis. Each returns "" once the servo thread
  // has taken it, or why it is refused (the machine is not on, path motion or homing under way, no
  // such axis, at the soft limit). Abort stops jogs under control; estop and off stop them at once.
  std::string jog_start(int axis, double velocity_per_s);  // sign = direction; until jog_stop
  std::string jog_increment(int axis, double distance, double speed_per_s);
  void jog_stop(int axis);  // controlled stop

  // After start(): how long a driver may take to report a drive that does not answer or has
  // faulted (the longest Driver::feedback_deadline_ns), 0 when every driver answers each
  // period.
  std::int64_t feedback_deadline_ns() const;

  // Lock-free copy of the latest status.
  Status status() const;
  // Takes the next event the servo thread posted (faults, warnings); false when none.
  bool poll_event(Event& event);
  // Warnings from start() (real-time scheduling or memory locking refused), for the log.
  const std::vector<std::string>& start_warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cncd::motion
