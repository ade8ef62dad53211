// Motion in step with the spindle (G33, G33.1, rigid G84/G74): where along a synchronized
// segment the path stands, taken each servo period from the spindle's measured position, and,
// for a tap, the speed the spindle is driven at. Every method is RT (servo thread); it knows
// nothing of drivers: MachineIo hands it the spindle as measured and applies its command.
//
// A tap (SpindleSync::tap) is rigid tapping as a rigid-tapping control does it: the spindle is
// brought to rest above the hole and its position locked there; then the spindle is driven
// down the hole along a speed ramp the axis can follow (the lower of the spindle's and the
// line's acceleration), braked to rest at the bottom, reversed, and braked to rest again where
// it was locked. The axis follows the spindle's position (one period ahead, by its speed), so
// it stays on the helix through the ramps and the reversal. The feed override scales the
// spindle's speed, and so the axis's, throughout.
//
// A thread (SpindleSync::thread, G33) takes the spindle as the program turns it: the path
// starts at the next whole revolution (the index) and catches up with the helix within the
// line's acceleration, follows it, and slows to rest at the line's end. A thread move that
// follows another one (a taper after the straight part of a G76 pass, a chain of G33 moves)
// goes on along the same helix: its path starts at the revolution where the helix left the
// previous move's end, so the thread stays in phase across the corner. Where the spindle has
// turned more than a revolution past that point (a hold between the two), the path waits for
// the next revolution in that phase instead.
#pragma once

#include <cstdint>

#include "cncd/drivers/rt.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

class SyncFollower {
 public:
  // The spindle this period.
  struct Spindle {
    double revolutions = 0;  // measured, signed (forward counts up)
    double rps = 0;          // measured, signed, revolutions per second
    int direction = 0;       // as programmed: 1 M3, -1 M4, 0 stopped
    double programmed_rps = 0;
    double max_rps = 1e300;       // the spindle's limit in the tap's direction
    double acceleration = 1e300;  // rev/s^2 the spindle can follow (its ramp)
    double stall_timeout_s = 0;   // a tap that makes no progress for this long fails
    double elapsed_s = 0;  // since the previous position, by the spindle's clock; 0: one period
    int command_delay_periods = 0;  // servo periods a speed command takes to reach the spindle
  };
  struct Step {
    double s = 0;                 // path position along the segment
    double v = 0;                 // path speed, >= 0
    bool done = false;            // the segment is over (s is its final position)
    bool drives_spindle = false;  // a tap: the spindle turns at `spindle_rps` this period
    double spindle_rps = 0;       // signed (forward > 0)
    RtEvent::Code error = RtEvent::Code::none;  // the move failed: the path stops
    double error_value = 0;                     // RtEvent::error and limit of the failure
    double error_limit = 0;
  };

  // RT: a synchronized segment starts, the spindle as measured; `continues`: a thread segment
  // that goes on along the helix of the thread segment that ended last.
  CNCD_RT void start(const Segment& segment, const Spindle& spindle,
                     bool continues = false) noexcept;
  // RT: one period of `dt` s. `feed_override` scales a tap's speed; `stop` (an abort) brings
  // the spindle (tap) or the path (thread) to rest, after which the step is done.
  CNCD_RT Step step(const Segment& segment, const Spindle& spindle, double feed_override, bool stop,
                    double dt) noexcept;
  // RT: the segment ended or was dropped.
  CNCD_RT void end() noexcept { status_ = {}; }
  CNCD_RT const SyncStatus& status() const noexcept { return status_; }

 private:
  CNCD_RT Step tap_step(const Segment& segment, const Spindle& spindle, double feed_override,
                        bool stop, double dt) noexcept;
  // Counts the time the spindle has been `stalled` in a row; past its timeout, the step fails.
  CNCD_RT void watch_stall(bool stalled, const Spindle& spindle, double dt, Step& out) noexcept;
  CNCD_RT Step thread_step(const Segment& segment, const Spindle& spindle, bool stop,
                           double dt) noexcept;

  SyncStatus status_{};
  int direction_ = 1;     // the spindle's direction into the hole / along the thread
  double origin_ = 0;     // spindle revolutions at the path's start (s = 0)
  double command_ = 0;    // tap: spindle speed commanded, rev/s, > 0 into the hole
  double accel_ = 0;      // tap: the ramp, rev/s^2
  double path_v_ = 0;     // thread: path speed
  double path_s_ = 0;     // thread: path position
  double helix_end_ = 0;  // thread: revolutions where the last one's helix reached its end
  bool has_helix_end_ = false;
  bool locked_ = false;       // tap: the spindle's position is locked to the path's
  bool out_at_top_ = false;   // tap: back at the top, told to stop
  double last_s_ = 0;         // tap: the path position given last period
  double stalled_s_ = 0;      // time without progress while driven
  double stopping_s_ = 0;     // tap: time spent bringing the spindle to rest
  int rest_periods_ = 0;      // tap: periods in a row the spindle has stood still
  double last_progress_ = 0;  // tap: revolutions into the hole in the previous period
  // tap: the latest speed commands (rev/s into the hole), newest at sent_[(sent_head_ - 1)]:
  // those sent within the spindle's command delay still turn it.
  static constexpr int kMaxDelayPeriods = 256;
  double sent_[kMaxDelayPeriods] = {};
  int sent_head_ = 0;
  CNCD_RT double still_to_turn(int periods, double dt) const noexcept;
};

}  // namespace cncd::motion
