// Turns programmed moves into segments whose every axis stays within its MAX_VELOCITY and
// MAX_ACCELERATION: the path limits are the tightest the axes allow along the move's direction
// (on arcs and blend arcs with the centripetal acceleration included), and [TRAJ]
// MAX_LINEAR_VELOCITY. Non-RT: called on the task thread.
//
// The stateful side (push/flush) looks one move ahead: it holds back the newest move until the
// next one shows how the two join. Tangent junctions are marked for the servo loop to cross
// at speed; under G64 a line-line corner gets a tangent blend arc within the P tolerance;
// every other junction stops (docs/motion.md).
#pragma once

#include <deque>
#include <optional>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class Planner {
 public:
  explicit Planner(const config::MachineConfig& config);

  // Plans `move` alone starting at `start` (it ends at rest). Returns nullopt and sets
  // `error` when the move cannot be made (a zero feed, an arc whose ends are not on one
  // circle, an end outside the soft limits of an axis in `check_limits`).
  std::optional<Segment> plan(const Move& move, const AxisPose& start, bool check_limits,
                              std::string& error) const;

  // Forgets any held move and output, and starts the next move at `start`.
  void reset(const AxisPose& start);
  // Plans `move` from where the last pushed move ends. The segments that are final go to
  // output(); the move itself may be held back until the next push() or flush(). False (with
  // `error`) when the move cannot be made; nothing changes then.
  bool push(const Move& move, bool check_limits, std::string& error);
  // Releases the held move, ending at rest: call before anything that must happen at rest or
  // in order (dwells, spindle and tool events, program stops and ends, the end of what the
  // interpreter has to give now).
  void flush();
  // Whether a move is held back.
  bool holding() const { return held_.has_value(); }
  // Where the last pushed move ends.
  const AxisPose& end() const { return end_; }
  // Final segments, oldest first, for the caller to take from the front.
  std::deque<Segment>& output() { return output_; }

 private:
  // Shares of a curve's in-plane acceleration limit for the tangential and the centripetal
  // part: at right angles, their sum stays within the limit (0.6^2 + 0.8^2 = 1).
  static constexpr double kTangentialShare = 0.6;
  static constexpr double kNormalShare = 0.8;

  bool within_limits(const Segment& segment, std::string& error) const;
  // Path speed and acceleration limits of a blend arc (blend_u, blend_v and radius set).
  void set_blend_limits(Segment& blend) const;
  // Joins the held segment to `next` (a planned move): marks a tangent junction, or inserts
  // a blend arc (trimming both lines), or leaves a stop. Emits the held segment.
  void join(Segment& next, const Move& move);

  struct Held {
    Segment segment;
    Move::PathMode mode = Move::PathMode::exact_stop;
    double tolerance = 0;
    double full_length = 0;  // before any blend trimmed it
    bool traverse = false;
  };

  const config::MachineConfig& config_;
  AxisPose end_{};
  std::optional<Held> held_;
  std::deque<Segment> output_;
};

}  // namespace cncd::motion
