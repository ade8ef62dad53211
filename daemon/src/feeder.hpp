// ProgramFeeder: the canonical-command sink that turns the interpreter's output into motion
// moves (machine coordinates and units) and remembers spindle, coolant and tool state.
// Used on the daemon's main loop thread.
#pragma once

#include <array>
#include <deque>

#include "cncd/interp/canon.hpp"
#include "cncd/interp/to_machine.hpp"
#include "cncd/motion/types.hpp"
#include "event_log.hpp"

namespace cncd::daemon {

class ProgramFeeder final : public interp::CanonSink {
 public:
  ProgramFeeder(interp::Units machine_units, EventLog& events)
      : tracker_(machine_units), events_(events) {}
  void emit(const interp::CanonCommand& command) override;
  // Resets what a new program run must not inherit.
  void start_program();
  // Whether `move` is a stop point (a zero dwell, G4 P0 included): nothing to execute, the
  // planner is flushed there.
  static bool stop_point(const motion::Move& move) {
    return move.kind == motion::Move::Kind::dwell && !(move.dwell_s > 0);
  }

  std::deque<motion::Move> pending;  // moves the planner had no room for yet
  bool stop_seen = false;            // M0/M1/M60 reached in the stream
  int spindle_direction = 0;         // 1 cw, -1 ccw, 0 stopped
  double spindle_speed = 0;          // rpm
  bool mist = false;
  bool flood = false;
  int tool = 0;

 private:
  interp::MachineTracker tracker_;
  EventLog& events_;
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

}  // namespace cncd::daemon
