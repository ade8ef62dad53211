// A planned move as the servo thread executes it: geometry in machine coordinates, and the
// path-speed and path-acceleration limits the planner derived from every axis's limits.
// Trivially copyable: it crosses the planner -> servo ring.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "cncd/motion/types.hpp"

namespace cncd::motion {

struct Segment {
  // blend: an arc in any plane (the tangent arc the planner puts into a corner).
  enum class Kind : std::uint8_t { line, arc, dwell, blend };
  Kind kind = Kind::line;
  AxisPose start{};
  AxisPose end{};
  double length = 0;            // path length (units); 0 for dwell
  double max_velocity = 0;      // path speed limit, units/s (feed, axis and arc limits)
  double axis_velocity = 0;     // path speed limit of the axes and the arc alone, units/s
  double feed = 0;              // programmed feed, units/s; 0 = traverse (rapid override)
  double feed_per_rev = 0;      // G95: units per spindle revolution (feed follows the spindle)
  double max_acceleration = 0;  // path acceleration limit, units/s^2
  double dwell_s = 0;
  // Arc: centre in the plane, radius at the start, start angle and signed sweep (rad), plane
  // axes. The radius goes linearly with the swept angle to radius + radius_change at the end:
  // a spiral where a program's rounded centre words put the end off the start's circle, within
  // the tolerance LinuxCNC allows (and runs the same way). The swept angle and every other axis
  // advance in proportion to the path distance; `length` is the path length at the larger
  // radius, so that the tool never goes faster than the planned path speed.
  std::int8_t first_axis = 0, second_axis = 1, normal_axis = 2;
  double center_first = 0, center_second = 0;
  double radius = 0;
  double radius_change = 0;
  double start_angle = 0;
  double sweep = 0;
  // Blend: point(phi) = blend_center + radius (cos(phi) blend_u + sin(phi) blend_v) for phi
  // from 0 to sweep; blend_u and blend_v are orthonormal over all axes.
  AxisPose blend_center{};
  AxisPose blend_u{};
  AxisPose blend_v{};
  // Fillet (a blend where a programmed arc meets a line or another arc, in the plane
  // first_axis/second_axis): the programmed corner it rounds, and the centre and radius of
  // each side that is an arc (radius 0: that side is a line). Only for measuring the
  // deviation from the programmed path; the servo loop follows blend_*.
  bool fillet = false;
  double corner_first = 0, corner_second = 0;
  double in_center_first = 0, in_center_second = 0, in_radius = 0;
  double out_center_first = 0, out_center_second = 0, out_radius = 0;
  std::int32_t line = 0;
  // A dwell that does this (Move::Kind::action) and is over once it is done.
  IoAction action;
  // Outputs set as the segment starts (the first segment of a move, or the blend arc into it).
  SyncOutputs sync;
  // A probing line: the servo loop stops it where the probe trips (ServoLoop::watch_probe).
  ProbeMode probe = ProbeMode::none;
  // In step with the spindle (Move::spindle_sync): the servo loop takes the path position from
  // the spindle's (MachineIo::follow).
  SpindleSync spindle_sync = SpindleSync::none;
  double per_rev = 0;
  double retract_scale = 1;
  // A piece of a move planned under TCP (Move::tcp on a table-rotary machine): the status
  // shows it while the segment runs and after, until the next one starts.
  bool tcp = false;
  double tool_length = 0;  // under TCP: Move::tool_length, the tip the table's turns carry
  // Unit tangents (over all axes) at the start and the end; zero for dwells and zero-length
  // moves.
  AxisPose start_direction{};
  AxisPose end_direction{};
  // The planner found the next segment tangent to this one (a blend arc included): the servo
  // loop may cross this segment's end at speed. False: the path stops at the end.
  bool continuous = false;
  // Highest speed at the end junction when continuous (a kink), units/s.
  double junction_velocity = 1e300;
  // Programmed moves that are complete once this segment is (0 for a blend arc, more than 1
  // when the planner folded zero-length moves into it).
  std::uint32_t moves = 1;

  // Point at path distance s in [0, length]. RT-safe.
  AxisPose point_at(double s) const noexcept;
};

// Calls `visit(s, axis)` for the points of an arc where its angle is a multiple of a quarter
// turn, in order, that can reach farthest: s is the path distance there and `axis` the plane
// axis that reaches farthest there (for a spiral, very near there). Nothing for other segments.
// The radius changes linearly with the angle, so along each way of each axis the farthest such
// point lies in the first or the last turn: only those are visited, and an arc of a hundred
// million turns (G2 ... P100000000) costs what one of two turns does. The one model of how far
// an arc reaches, shared by the planner's soft-limit check and the offline check of a program.
template <typename Visit>
void for_each_arc_extreme(const Segment& segment, Visit&& visit) {
  if (segment.kind != Segment::Kind::arc || segment.sweep == 0) return;
  const double quarter = std::numbers::pi / 2;
  const double end_angle = segment.start_angle + segment.sweep;
  const double from = std::min(segment.start_angle, end_angle);
  const double to = std::max(segment.start_angle, end_angle);
  const double first = std::ceil(from / quarter);
  double last = std::floor(to / quarter);
  while (last * quarter > to)
    last -= 1;
  const auto at = [&](double k) {
    const int axis = std::fmod(std::abs(k), 2.0) == 0 ? segment.first_axis : segment.second_axis;
    visit(segment.length * (k * quarter - segment.start_angle) / segment.sweep, axis);
  };
  for (double k = first; k <= last && k < first + 4; k += 1)
    at(k);
  for (double k = std::max(first + 4, last - 3); k <= last; k += 1)
    at(k);
}

}  // namespace cncd::motion
