#include "feeder.hpp"

#include <algorithm>

namespace cncd::daemon {
namespace {

// The (first, second, normal) axes of an arc's plane, as LinuxCNC's ARC_FEED orders them.
std::array<int, 3> plane_axes(interp::Plane plane) {
  switch (plane) {
    case interp::Plane::yz:
      return {1, 2, 0};
    case interp::Plane::xz:
      return {2, 0, 1};
    case interp::Plane::xy:
    default:
      return {0, 1, 2};
  }
}

}  // namespace

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
      // G61 and G64 go on at speed through tangent junctions; G61.1 stops after every move.
      continuous_ = m.ivalue != static_cast<int>(interp::MotionMode::exact_stop);
      return;
    case interp::CanonKind::program_stop:
    case interp::CanonKind::optional_program_stop:
    case interp::CanonKind::pallet_shuttle:
      stop_seen = true;
      return;
    case interp::CanonKind::start_spindle_clockwise:
      spindle_direction = 1;
      return;
    case interp::CanonKind::start_spindle_counterclockwise:
      spindle_direction = -1;
      return;
    case interp::CanonKind::stop_spindle_turning:
      spindle_direction = 0;
      return;
    case interp::CanonKind::set_spindle_speed:
      spindle_speed = m.value;
      return;
    case interp::CanonKind::mist_on:
      mist = true;
      return;
    case interp::CanonKind::mist_off:
      mist = false;
      return;
    case interp::CanonKind::flood_on:
      flood = true;
      return;
    case interp::CanonKind::flood_off:
      flood = false;
      return;
    case interp::CanonKind::change_tool:
    case interp::CanonKind::change_tool_number:
      tool = m.ivalue;
      return;
    case interp::CanonKind::message:
      events_.add("info", "message", "line " + std::to_string(m.line) + ": " + m.text);
      return;
    default:
      return;
  }
  move.continuous = continuous_;
  pending.push_back(move);
}

}  // namespace cncd::daemon
