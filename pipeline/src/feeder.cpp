#include "cncd/pipeline/feeder.hpp"

#include <algorithm>

#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {
void ProgramFeeder::start_program() {
  pending.clear();
  stop_seen = false;
}

void ProgramFeeder::emit(const interp::CanonCommand& command) {
  const interp::CanonCommand m = tracker_.to_machine(command);
  motion::Move move;
  move.line = m.line;
  switch (m.kind) {
    case interp::CanonKind::straight_traverse:
      move.kind = motion::Move::Kind::traverse;
      std::copy(m.pos.begin(), m.pos.end(), move.end.begin());
      break;
    case interp::CanonKind::straight_feed:
      move.kind = motion::Move::Kind::feed;
      std::copy(m.pos.begin(), m.pos.end(), move.end.begin());
      move.feed = tracker_.feed_per_minute() / 60.0;
      break;
    case interp::CanonKind::arc_feed:
      move.kind = motion::Move::Kind::arc;
      std::copy(m.pos.begin(), m.pos.end(), move.end.begin());
      move.feed = tracker_.feed_per_minute() / 60.0;
      move.plane_axes = plane_axes(m.plane);
      move.center_first = m.first_axis;
      move.center_second = m.second_axis;
      move.turns = m.rotation;
      break;
    case interp::CanonKind::dwell:
      move.kind = motion::Move::Kind::dwell;
      move.dwell_s = m.value;
      break;
    case interp::CanonKind::set_motion_control_mode:
      // G61.1 stops after every move, G61 only where the path turns (and, as canned cycles
      // run in G61, where a traverse meets a feed move), G64 blends corners within P.
      path_mode_ = m.ivalue == static_cast<int>(interp::MotionMode::exact_stop)
                       ? motion::Move::PathMode::exact_stop
                   : m.ivalue == static_cast<int>(interp::MotionMode::exact_path)
                       ? motion::Move::PathMode::exact_path
                       : motion::Move::PathMode::blend;
      tolerance_ = std::max(0.0, m.value * tracker_.length_factor());
      return;
    case interp::CanonKind::set_naivecam_tolerance:
      merge_tolerance_ = std::max(0.0, m.value * tracker_.length_factor());
      return;
    case interp::CanonKind::program_stop:
    case interp::CanonKind::optional_program_stop:
      stop_seen = true;
      return;
    case interp::CanonKind::pallet_shuttle:
      // No pallet changer to drive. M60 pauses through the PROGRAM_STOP that follows it; M30
      // ends the program, as M2 does.
      return;
    case interp::CanonKind::start_spindle_clockwise:
      add_stop_point();
      spindle_direction = 1;
      return;
    case interp::CanonKind::start_spindle_counterclockwise:
      add_stop_point();
      spindle_direction = -1;
      return;
    case interp::CanonKind::stop_spindle_turning:
      add_stop_point();
      spindle_direction = 0;
      return;
    case interp::CanonKind::set_spindle_speed:
      add_stop_point();
      spindle_speed = m.value;
      return;
    case interp::CanonKind::mist_on:
      add_stop_point();
      mist = true;
      return;
    case interp::CanonKind::mist_off:
      add_stop_point();
      mist = false;
      return;
    case interp::CanonKind::flood_on:
      add_stop_point();
      flood = true;
      return;
    case interp::CanonKind::flood_off:
      add_stop_point();
      flood = false;
      return;
    case interp::CanonKind::change_tool:
    case interp::CanonKind::change_tool_number:
      add_stop_point();
      tool = m.ivalue;
      return;
    case interp::CanonKind::message:
      if (on_message_) on_message_(m.line, m.text);
      return;
    default:
      return;
  }
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
