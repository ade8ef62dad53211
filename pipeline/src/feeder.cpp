#include "cncd/pipeline/feeder.hpp"

#include <algorithm>
#include <variant>

#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {
void ProgramFeeder::start_program() {
  pending.clear();
  stop_seen = false;
}

void ProgramFeeder::emit(const interp::CanonCommand& command) {
  namespace in = interp;
  const in::CanonCommand m = tracker_.to_machine(command);
  motion::Move move;
  move.line = m.line;
  // Spindle, coolant and tool events queue no move; they mark a stop point.
  auto spindle = [&](int direction) {
    add_stop_point();
    spindle_direction = direction;
    return false;
  };
  auto coolant = [&](bool& flag, bool on) {
    add_stop_point();
    flag = on;
    return false;
  };
  auto tool_change = [&](int number) {
    add_stop_point();
    tool = number;
    return false;
  };
  auto stop = [&] {
    stop_seen = true;
    return false;
  };
  const bool queued = std::visit(
      in::Overloaded{
          [&](const in::StraightTraverse& c) {
            move.kind = motion::Move::Kind::traverse;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            return true;
          },
          [&](const in::StraightFeed& c) {
            move.kind = motion::Move::Kind::feed;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            move.feed = tracker_.feed_per_minute() / 60.0;
            return true;
          },
          [&](const in::ArcFeed& c) {
            move.kind = motion::Move::Kind::arc;
            const in::Pose end = c.end();
            std::copy(end.begin(), end.end(), move.end.begin());
            move.feed = tracker_.feed_per_minute() / 60.0;
            move.plane_axes = plane_axes(c.plane);
            move.center_first = c.first_axis;
            move.center_second = c.second_axis;
            move.turns = c.rotation;
            return true;
          },
          [&](const in::Dwell& c) {
            move.kind = motion::Move::Kind::dwell;
            move.dwell_s = c.seconds;
            return true;
          },
          [&](const in::SetMotionControlMode& c) {
            // G61.1 stops after every move, G61 only where the path turns (and, as canned
            // cycles run in G61, where a traverse meets a feed move), G64 blends corners
            // within P.
            path_mode_ = c.mode == in::MotionMode::exact_stop   ? motion::Move::PathMode::exact_stop
                         : c.mode == in::MotionMode::exact_path ? motion::Move::PathMode::exact_path
                                                                : motion::Move::PathMode::blend;
            tolerance_ = std::max(0.0, c.tolerance * tracker_.length_factor());
            return false;
          },
          [&](const in::SetNaivecamTolerance& c) {
            merge_tolerance_ = std::max(0.0, c.tolerance * tracker_.length_factor());
            return false;
          },
          [&](const in::ProgramStop&) { return stop(); },
          [&](const in::OptionalProgramStop&) { return stop(); },
          [&](const in::StartSpindleClockwise&) { return spindle(1); },
          [&](const in::StartSpindleCounterclockwise&) { return spindle(-1); },
          [&](const in::StopSpindleTurning&) { return spindle(0); },
          [&](const in::SetSpindleSpeed& c) {
            add_stop_point();
            spindle_speed = c.rpm;
            return false;
          },
          [&](const in::MistOn&) { return coolant(mist, true); },
          [&](const in::MistOff&) { return coolant(mist, false); },
          [&](const in::FloodOn&) { return coolant(flood, true); },
          [&](const in::FloodOff&) { return coolant(flood, false); },
          [&](const in::ChangeTool& c) { return tool_change(c.tool); },
          [&](const in::ChangeToolNumber& c) { return tool_change(c.tool); },
          [&](const in::Message& c) {
            if (on_message_) on_message_(m.line, c.text);
            return false;
          },
          // No pallet changer to drive: M60 pauses through the ProgramStop that follows it;
          // M30 ends the program, as M2 does.
          [](const auto&) { return false; },
      },
      m.op);
  if (!queued) return;
  move.path_mode = path_mode_;
  move.tolerance = tolerance_;
  move.merge_tolerance = path_mode_ == motion::Move::PathMode::blend ? merge_tolerance_ : 0.0;
  pending.push_back(move);
}

Drained ProgramFeeder::drain(MoveTarget& target) {
  while (!pending.empty()) {
    if (!target.ready()) return {MoveTarget::Push::full, 0};
    const motion::Move& move = pending.front();
    if (stop_point(move)) {
      target.flush();
      pending.pop_front();
      continue;
    }
    const MoveTarget::Push result = target.push(move);
    if (result != MoveTarget::Push::accepted) return {result, move.line};
    pending.pop_front();
  }
  return {};
}

void ProgramFeeder::add_stop_point() {
  if (!pending.empty() && stop_point(pending.back())) return;
  motion::Move stop;
  stop.kind = motion::Move::Kind::dwell;
  stop.dwell_s = 0;
  pending.push_back(stop);
}

}  // namespace cncd::pipeline
