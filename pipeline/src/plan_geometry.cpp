#include "cncd/pipeline/plan_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cncd::pipeline {
namespace {

double xyz_distance(const motion::AxisPose& a, const motion::AxisPose& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

}  // namespace

MoveLimits move_limits(const config::MachineConfig& machine, const motion::Segment& segment) {
  MoveLimits limits;
  if (segment.kind == motion::Segment::Kind::dwell || segment.length <= 0) return limits;
  double v = 1e300;
  double a = 1e300;
  bool linear = false;
  for (int i = 0; i < motion::kAxes; ++i) {
    const auto& axis = machine.axes[static_cast<std::size_t>(i)];
    if (!axis.present) continue;
    const double share = std::abs(segment.end[i] - segment.start[i]) / segment.length;
    if (share <= 1e-12) continue;
    linear = linear || i < 3;
    v = std::min(v, axis.max_velocity / share);
    a = std::min(a, axis.max_acceleration / share);
  }
  if (linear && machine.max_linear_velocity > 0) v = std::min(v, machine.max_linear_velocity);
  if (segment.feed > 0) v = std::min(v, segment.feed);
  // A full circle moves no axis from end to end: the feed alone bounds it.
  limits.velocity = v < 1e300 ? v : (segment.feed > 0 ? segment.feed : 1e300);
  limits.acceleration = a;
  return limits;
}

double rest_to_rest_s(double length, double velocity, double acceleration) {
  if (length <= 0) return 0;
  if (!(velocity < 1e300)) return 0;
  if (!(acceleration < 1e300)) return length / velocity;
  // Reaches `velocity` when the length allows the ramps up and down, else a triangle.
  if (length >= velocity * velocity / acceleration)
    return length / velocity + velocity / acceleration;
  return 2.0 * std::sqrt(length / acceleration);
}

double distance_to_path(const motion::Segment& segment, const motion::AxisPose& point) {
  using Kind = motion::Segment::Kind;
  if (segment.kind == Kind::dwell || segment.length <= 0) return xyz_distance(segment.end, point);
  if (segment.kind == Kind::line) {
    double along = 0;
    double squared = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = segment.end[i] - segment.start[i];
      along += (point[i] - segment.start[i]) * d;
      squared += d * d;
    }
    if (squared <= 1e-24) return xyz_distance(segment.start, point);
    const double f = std::clamp(along / squared, 0.0, 1.0);
    motion::AxisPose nearest{};
    for (int i = 0; i < 3; ++i)
      nearest[i] = segment.start[i] + f * (segment.end[i] - segment.start[i]);
    return xyz_distance(nearest, point);
  }
  if (segment.kind == Kind::blend && segment.fillet) {
    // A fillet rounds a corner where an arc meets a line or another arc, in the plane of
    // first_axis and second_axis: the programmed path is what it cut from each side, from
    // where it leaves the first curve to the corner and from the corner to where it joins the
    // second. An arc side's piece is less than half a turn.
    const int a = segment.first_axis, b = segment.second_axis;
    motion::AxisPose corner = segment.start;
    corner[a] = segment.corner_first;
    corner[b] = segment.corner_second;
    auto piece = [&](const motion::AxisPose& from, const motion::AxisPose& to, double cx, double cy,
                     double radius) {
      motion::Segment s;
      s.start = from;
      s.end = to;
      if (radius <= 0) {
        s.kind = Kind::line;
        s.length = xyz_distance(from, to);
        return s;
      }
      s.kind = Kind::arc;
      s.first_axis = segment.first_axis;
      s.second_axis = segment.second_axis;
      s.center_first = cx;
      s.center_second = cy;
      s.radius = radius;
      s.start_angle = std::atan2(from[b] - cy, from[a] - cx);
      s.sweep =
          std::remainder(std::atan2(to[b] - cy, to[a] - cx) - s.start_angle, 2 * std::numbers::pi);
      s.length = radius * std::abs(s.sweep);
      return s;
    };
    const motion::Segment in = piece(segment.start, corner, segment.in_center_first,
                                     segment.in_center_second, segment.in_radius);
    const motion::Segment out = piece(corner, segment.end, segment.out_center_first,
                                      segment.out_center_second, segment.out_radius);
    return std::min(distance_to_path(in, point), distance_to_path(out, point));
  }
  if (segment.kind == Kind::blend) {
    // The programmed path here is the corner the blend arc rounds: from where the arc leaves
    // the first line to the corner, and on to where it joins the second.
    const double reach = segment.radius * std::tan(0.5 * segment.sweep);
    motion::Segment in = segment;
    in.kind = Kind::line;
    for (int i = 0; i < motion::kAxes; ++i)
      in.end[i] = segment.start[i] + reach * segment.start_direction[i];
    in.length = reach;
    motion::Segment out = in;
    out.start = in.end;
    out.end = segment.end;
    return std::min(distance_to_path(in, point), distance_to_path(out, point));
  }
  // Arc: the candidates are the ends and, on every turn the sweep covers, the point at the
  // sample's angle about the centre (a spiral's angle goes in proportion to the distance).
  double best = std::min(xyz_distance(segment.start, point), xyz_distance(segment.end, point));
  const double angle = std::atan2(point[segment.second_axis] - segment.center_second,
                                  point[segment.first_axis] - segment.center_first);
  const double two_pi = 2 * std::numbers::pi;
  const double sweep = std::abs(segment.sweep);
  double offset = segment.sweep >= 0 ? angle - segment.start_angle : segment.start_angle - angle;
  offset = std::fmod(offset, two_pi);
  if (offset < 0) offset += two_pi;
  for (int turn = 0; offset <= sweep && turn < 64; ++turn, offset += two_pi)
    best = std::min(best, xyz_distance(segment.point_at(segment.length * offset / sweep), point));
  return best;
}

}  // namespace cncd::pipeline
