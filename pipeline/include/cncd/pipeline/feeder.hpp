// ProgramFeeder: the canonical-command sink that turns the interpreter's output into motion
// moves (machine coordinates and units) and remembers spindle, coolant and tool state, and
// the loop that hands those moves on (drain). The daemon's task feeds them to the motion
// controller, the plan simulation to a planner of its own: both read a program the same way.
// One thread at a time.
#pragma once

#include <deque>
#include <functional>
#include <string>

#include "cncd/interp/canon.hpp"
#include "cncd/interp/to_machine.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::pipeline {

// Where drain() hands the moves: the motion controller's queue or a planner.
class MoveTarget {
 public:
  enum class Push { accepted, full, refused };
  virtual ~MoveTarget() = default;
  // Whether the next move may be handed on now (a stop point included).
  virtual bool ready() { return true; }
  virtual Push push(const motion::Move& move) = 0;
  // A stop point: the move held back for look-ahead goes out, the path comes to rest there.
  virtual void flush() = 0;
};

struct Drained {
  MoveTarget::Push result = MoveTarget::Push::accepted;  // accepted: nothing left pending
  int line = 0;                                          // the refused move's line
};

class ProgramFeeder final : public interp::CanonSink {
 public:
  // Operator messages (MSG) in the program, with their line; none = dropped.
  using MessageHandler = std::function<void(int line, const std::string& text)>;

  explicit ProgramFeeder(interp::Units machine_units, MessageHandler on_message = {})
      : tracker_(machine_units), on_message_(std::move(on_message)) {}
  void emit(const interp::CanonCommand& command) override;
  // Resets what a new program run must not inherit.
  void start_program();
  // Whether `move` is a stop point (a zero dwell, G4 P0 included): nothing to execute, the
  // planner is flushed there.
  static bool stop_point(const motion::Move& move) {
    return move.kind == motion::Move::Kind::dwell && !(move.dwell_s > 0);
  }
  // Hands the pending moves to `target` in order, flushing it at stop points, until none is
  // left, the target has no room, or it refuses one (which stays pending).
  Drained drain(MoveTarget& target);
  // Offsets, units and feed as the commands so far left them.
  const interp::MachineTracker& tracker() const { return tracker_; }

  std::deque<motion::Move> pending;  // moves the planner had no room for yet
  bool stop_seen = false;            // M0/M1/M60 reached in the stream
  int spindle_direction = 0;         // 1 cw, -1 ccw, 0 stopped
  double spindle_speed = 0;          // rpm
  bool mist = false;
  bool flood = false;
  int tool = 0;

 private:
  interp::MachineTracker tracker_;
  MessageHandler on_message_;
  // Queues a stop point (a zero dwell) where a spindle, coolant or tool event comes in the
  // program, for the task to flush the planner there: the path comes to rest at that point
  // instead of blending through it.
  void add_stop_point();

  // Path control mode and G64 P tolerance (machine units) as the interpreter last set them
  // (it starts in G64 and keeps its modes from one program to the next, as this feeder does).
  motion::Move::PathMode path_mode_ = motion::Move::PathMode::blend;
  double tolerance_ = 0;
  double merge_tolerance_ = 0;  // G64 Q
};

}  // namespace cncd::pipeline
