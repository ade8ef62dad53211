#include "cncd/motion/planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "cncd/motion/path_executor.hpp"
#include "cncd/motion/soft_limits.hpp"

namespace cncd::motion {
namespace {

constexpr double kTiny = 1e-12;
// Relative radius differences below this are rounding, not a program's spiral.
constexpr double kRoundOff = 1e-9;

// LinuxCNC lets a centre-format arc's end radius differ from its start radius by up to
// 0.002 sqrt(2) in with G20 (0.02 sqrt(2) mm with G21), or by up to 0.1 % of the larger
// radius but never more than 100 times that; the interpreter refuses the rest with LinuxCNC's
// message. The planner takes anything the interpreter may pass in either unit (the inch
// figures are the looser), with room for rounding through units, offsets and rotation: more
// is not a program's arc.
constexpr double kArcToleranceInch = 0.0028284271247461905;
constexpr double kArcRelativeTolerance = 0.001;
constexpr double kArcToleranceCap = 100.0;

// `tolerance`: kArcToleranceInch in machine units.
bool arc_radii_agree(double r0, double r1, double tolerance) {
  constexpr double kSlack = 1.0 + 1e-6;
  const double difference = std::abs(r1 - r0);
  if (difference > kArcToleranceCap * tolerance * kSlack) return false;
  return difference <= tolerance * kSlack ||
         difference <= kArcRelativeTolerance * kSlack * std::max(r0, r1);
}

double plane_rate(const Segment& seg) {
  // The in-plane speed per unit of the swept fraction, at the larger radius.
  const double r_max = std::max(seg.radius, seg.radius + seg.radius_change);
  return std::hypot(std::abs(seg.sweep) * r_max, seg.radius_change);
}

// LinuxCNC measures feed along XYZ when they move, else along UVW, else along ABC.
double path_length(const AxisPose& delta) {
  auto norm = [&](int first) {
    return std::sqrt(delta[first] * delta[first] + delta[first + 1] * delta[first + 1] +
                     delta[first + 2] * delta[first + 2]);
  };
  const double xyz = norm(0);
  if (xyz > kTiny) return xyz;
  const double uvw = norm(6);
  if (uvw > kTiny) return uvw;
  return norm(3);
}

}  // namespace

AxisPose Segment::point_at(double s) const noexcept {
  if (kind == Kind::dwell || length <= 0) return end;
  const double f = std::clamp(s / length, 0.0, 1.0);
  AxisPose p{};
  if (kind == Kind::blend) {
    if (f >= 1.0) return end;
    const double c = radius * std::cos(sweep * f);
    const double n = radius * std::sin(sweep * f);
    for (int i = 0; i < kAxes; ++i)
      p[i] = blend_center[i] + c * blend_u[i] + n * blend_v[i];
    return p;
  }
  for (int i = 0; i < kAxes; ++i)
    p[i] = start[i] + (end[i] - start[i]) * f;
  if (kind == Kind::arc) {
    const double angle = start_angle + sweep * f;
    const double r = radius + radius_change * f;
    p[first_axis] = center_first + r * std::cos(angle);
    p[second_axis] = center_second + r * std::sin(angle);
    if (f >= 1.0) {
      p[first_axis] = end[first_axis];
      p[second_axis] = end[second_axis];
    }
  }
  return p;
}

Planner::Planner(const config::MachineConfig& config)
    : config_(config),
      kins_(make_kinematics(config)),
      jerk_(PathExecutor::jerk_limit(config, static_cast<double>(config.servo_period_ns) * 1e-9)) {}

void Planner::set_directions(Segment& seg) {
  AxisPose start{}, end{};
  for (int i = 0; i < kAxes; ++i)
    start[i] = end[i] = seg.end[i] - seg.start[i];
  if (seg.kind == Segment::Kind::arc) {
    // d(in-plane position)/d(fraction of the sweep): radius x sweep across the radius, plus
    // the radius change along it (a spiral's).
    auto tangent = [&](double angle, double radius, AxisPose& d) {
      const double k = radius * seg.sweep;
      d[seg.first_axis] = seg.radius_change * std::cos(angle) - k * std::sin(angle);
      d[seg.second_axis] = seg.radius_change * std::sin(angle) + k * std::cos(angle);
    };
    tangent(seg.start_angle, seg.radius, start);
    tangent(seg.start_angle + seg.sweep, seg.radius + seg.radius_change, end);
  }
  auto normalize = [](AxisPose& d) {
    double sum = 0;
    for (double x : d)
      sum += x * x;
    const double n = std::sqrt(sum);
    for (double& x : d)
      x = n > kTiny ? x / n : 0.0;
  };
  normalize(start);
  normalize(end);
  seg.start_direction = start;
  seg.end_direction = end;
}

void Planner::curve_limits(double fastest, double radius, double plane_a, double max_normal,
                           double& v, double& a) {
  // The tangential and centripetal parts are at right angles: shares t and n of the in-plane
  // limit with t^2 + n^2 = 1 keep their sum, and so every axis of the plane, within it. The
  // centripetal part gets what the fastest speed needs (the rest speeds up and slows down),
  // at most `max_normal`; beyond, the curve limits the speed. Either way the speed is limited
  // to what that share allows (the fastest speed asked for, when it fits): a path that does not
  // slow down to its feed in time (S-curve profiles under a lowered override) is still held to
  // what the axes allow on the curve.
  const double needed = fastest * fastest / (radius * plane_a);
  const double normal = std::min(needed, max_normal);
  v = std::min(v, std::sqrt(normal * plane_a * radius));
  a = std::sqrt(1.0 - normal * normal) * plane_a;
}

namespace {

// A coordinate as messages show it: four decimals, or (for the absurd ones, where %.4f would
// print hundreds of digits) its ten significant ones.
void format_coordinate(char* out, std::size_t size, double value) {
  std::snprintf(out, size, std::fabs(value) <= kMaxCoordinate ? "%.4f" : "%.10g", value);
}

void limit_error(std::string& error, int axis, double value, double min, double max) {
  char v[40], lo[40], hi[40];
  format_coordinate(v, sizeof v, value);
  format_coordinate(lo, sizeof lo, min);
  format_coordinate(hi, sizeof hi, max);
  const char letter = config::kAxisLetters[static_cast<std::size_t>(axis)];
  char text[200];
  std::snprintf(text, sizeof text, "move to %c %s is outside the %c soft limits [%s, %s]", letter,
                v, letter, lo, hi);
  error = text;
}

}  // namespace

bool Planner::within_limits(const Segment& segment, std::string& error) const {
  const auto inside = [&](double s) {
    const AxisPose p = segment.point_at(s);
    for (int i = 0; i < kAxes; ++i) {
      const auto& axis = config_.axes[static_cast<std::size_t>(i)];
      if (!axis.present) continue;
      // Written so that a NaN is outside.
      if (!(p[i] >= axis.min_limit - kSoftLimitSlack && p[i] <= axis.max_limit + kSoftLimitSlack)) {
        limit_error(error, i, p[i], axis.min_limit, axis.max_limit);
        return false;
      }
    }
    return true;
  };
  // Lines are convex: their ends suffice. Arcs are sampled in 256 steps (a chord error below
  // 1e-4 of the radius); in its plane an arc reaches farthest where its angle is a multiple
  // of a quarter turn (a spiral very near there), and a bulge that small between two samples
  // would be missed: those points are checked too, where the offline check finds them.
  const int samples = segment.kind == Segment::Kind::arc ? 256 : 1;
  for (int k = 0; k <= samples; ++k) {
    if (!inside(segment.length * k / samples)) return false;
  }
  bool ok = true;
  for_each_arc_extreme(segment, [&](double s, int) { ok = ok && inside(s); });
  return ok;
}

std::optional<Segment> Planner::plan(const Move& move, const AxisPose& start, bool check_limits,
                                     std::string& error) const {
  // A NaN passes every comparison with a limit: refuse it before it reaches a motor.
  bool finite = std::isfinite(move.feed) && std::isfinite(move.dwell_s) &&
                std::isfinite(move.center_first) && std::isfinite(move.center_second);
  for (int i = 0; i < kAxes; ++i)
    finite = finite && std::isfinite(move.end[i]) && std::isfinite(start[i]);
  if (!finite) {
    error = "move has a non-finite coordinate, feed or time";
    return std::nullopt;
  }
  // Beyond kMaxCoordinate the path arithmetic itself overflows (a length of infinity makes
  // every point NaN): refused homed or not, with the soft limits when they apply.
  const bool rests = move.kind == Move::Kind::dwell || move.kind == Move::Kind::action;
  if (!rests) {
    for (int i = 0; i < kAxes; ++i) {
      const auto& axis = config_.axes[static_cast<std::size_t>(i)];
      if (!axis.present || std::fabs(move.end[i]) <= kMaxCoordinate) continue;
      if (check_limits) {
        limit_error(error, i, move.end[i], axis.min_limit, axis.max_limit);
      } else {
        char v[40];
        format_coordinate(v, sizeof v, move.end[i]);
        error = std::string("move to ") + config::kAxisLetters[static_cast<std::size_t>(i)] + " " +
                v + " is beyond 1e9, the largest coordinate any move may have";
      }
      return std::nullopt;
    }
    if (move.kind == Move::Kind::arc && (std::fabs(move.center_first) > kMaxCoordinate ||
                                         std::fabs(move.center_second) > kMaxCoordinate)) {
      error = "arc centre is beyond 1e9, the largest coordinate any move may have";
      return std::nullopt;
    }
  }
  if (move.kind == Move::Kind::arc) {
    for (int axis : move.plane_axes) {
      if (axis < 0 || axis >= kAxes) {
        error = "arc plane names an axis that does not exist";
        return std::nullopt;
      }
    }
    if (move.plane_axes[0] == move.plane_axes[1] || move.plane_axes[0] == move.plane_axes[2] ||
        move.plane_axes[1] == move.plane_axes[2]) {
      error = "arc plane axes must differ";
      return std::nullopt;
    }
  }
  Segment seg;
  seg.start = start;
  seg.end = rests ? start : move.end;
  seg.line = move.line;
  seg.sync = move.sync;
  seg.probe = move.kind == Move::Kind::feed ? move.probe : ProbeMode::none;
  if (move.kind == Move::Kind::feed && move.spindle_sync != SpindleSync::none) {
    if (!(move.per_rev > 0) || !std::isfinite(move.per_rev) || !(move.retract_scale >= 1) ||
        !std::isfinite(move.retract_scale)) {
      error = "spindle-synchronized move needs a positive distance per revolution";
      return std::nullopt;
    }
    seg.spindle_sync = move.spindle_sync;
    seg.per_rev = move.per_rev;
    seg.retract_scale = move.retract_scale;
  }
  for (int i = 0; i < kAxes; ++i) {
    if (!config_.axes[static_cast<std::size_t>(i)].present) seg.end[i] = start[i];
  }
  if (rests) {
    seg.kind = Segment::Kind::dwell;
    seg.dwell_s = move.kind == Move::Kind::dwell ? std::max(0.0, move.dwell_s) : 0.0;
    if (move.kind == Move::Kind::action) {
      // An action is no programmed move: Status::actions_done counts it instead.
      seg.action = move.action;
      seg.moves = 0;
    }
    return seg;
  }
  if (move.kind != Move::Kind::traverse && !(move.feed > 0)) {
    error = "feed rate is zero";
    return std::nullopt;
  }
  AxisPose delta{};
  for (int i = 0; i < kAxes; ++i)
    delta[i] = seg.end[i] - start[i];

  if (move.kind == Move::Kind::arc) {
    seg.kind = Segment::Kind::arc;
    seg.first_axis = static_cast<std::int8_t>(move.plane_axes[0]);
    seg.second_axis = static_cast<std::int8_t>(move.plane_axes[1]);
    seg.normal_axis = static_cast<std::int8_t>(move.plane_axes[2]);
    seg.center_first = move.center_first;
    seg.center_second = move.center_second;
    const double r0 = std::hypot(start[seg.first_axis] - move.center_first,
                                 start[seg.second_axis] - move.center_second);
    const double r1 = std::hypot(seg.end[seg.first_axis] - move.center_first,
                                 seg.end[seg.second_axis] - move.center_second);
    if (r0 < kTiny || r1 < kTiny) {
      error = "arc starts or ends at its centre";
      return std::nullopt;
    }
    if (!arc_radii_agree(r0, r1, kArcToleranceInch * 25.4 / config_.mm_per_unit())) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "arc radius differs between start and end by %.6g (%.6g to %.6g), more than "
                    "any program's arc may",
                    std::abs(r1 - r0), r0, r1);
      error = text;
      return std::nullopt;
    }
    seg.radius = r0;
    // Below rounding noise the arc stays a circle (the end point is still reached exactly):
    // fillets round only circles.
    if (std::abs(r1 - r0) > kRoundOff * std::max(1.0, r0)) seg.radius_change = r1 - r0;
    seg.start_angle = std::atan2(start[seg.second_axis] - move.center_second,
                                 start[seg.first_axis] - move.center_first);
    const double end_angle = std::atan2(seg.end[seg.second_axis] - move.center_second,
                                        seg.end[seg.first_axis] - move.center_first);
    const double two_pi = 2 * std::numbers::pi;
    double sweep = end_angle - seg.start_angle;
    const int turns = move.turns == 0 ? 1 : move.turns;
    if (turns > 0) {
      while (sweep <= 1e-12)
        sweep += two_pi;
      sweep += two_pi * (turns - 1);
    } else {
      while (sweep >= -1e-12)
        sweep -= two_pi;
      sweep -= two_pi * (-turns - 1);
    }
    seg.sweep = sweep;
    const double arc_length = plane_rate(seg);
    double other = 0;
    for (int i = 0; i < kAxes; ++i) {
      if (i != seg.first_axis && i != seg.second_axis) other += delta[i] * delta[i];
    }
    seg.length = std::sqrt(arc_length * arc_length + other);
  } else {
    seg.kind = Segment::Kind::line;
    seg.length = path_length(delta);
    // A move of only unlisted or rotary axes still has a length along what moves.
    if (seg.length <= kTiny) {
      double sum = 0;
      for (double d : delta)
        sum += d * d;
      seg.length = std::sqrt(sum);
    }
    if (seg.length <= kTiny) seg.length = 0;
  }
  if (check_limits && !within_limits(seg, error)) return std::nullopt;
  if (seg.length == 0) {
    seg.max_velocity = 1;
    seg.axis_velocity = 1;
    seg.max_acceleration = 1;
    return seg;
  }

  seg.feed = move.kind == Move::Kind::traverse ? 0.0 : move.feed;
  seg.feed_per_rev =
      move.kind != Move::Kind::traverse && std::isfinite(move.feed_per_rev) && move.feed_per_rev > 0
          ? move.feed_per_rev
          : 0.0;
  set_limits(seg);
  return seg;
}

void Planner::set_limits(Segment& seg) const {
  // Direction cosines along the path, per axis: for a line constant, for an arc the in-plane
  // axes reach 1 somewhere on a large enough sweep, so they are bounded by 1 (times the
  // in-plane share of the speed, which for a spiral is largest at its larger radius).
  AxisPose direction{};
  const bool arc = seg.kind == Segment::Kind::arc;
  const double arc_length = arc ? plane_rate(seg) : 0.0;
  for (int i = 0; i < kAxes; ++i) {
    const bool in_plane = arc && (i == seg.first_axis || i == seg.second_axis);
    direction[i] = (in_plane ? arc_length : std::abs(seg.end[i] - seg.start[i])) / seg.length;
  }
  // Each bound's rate along the path the same way: its share of the plane (the length of
  // its coefficients there) times the in-plane share, plus its part along the other axes.
  const double in_plane = arc ? direction[seg.first_axis] : 0.0;  // cos b, b the helix angle
  std::array<double, kMaxRateLimits> plane_share{};
  std::array<double, kMaxRateLimits> other_share{};
  AxisPose other{};
  for (int i = 0; i < kAxes; ++i) {
    const bool in_the_plane = arc && (i == seg.first_axis || i == seg.second_axis);
    other[i] = in_the_plane ? 0.0 : seg.end[i] - seg.start[i];
  }
  const auto limits = kins_->rate_limits();
  for (std::size_t r = 0; r < limits.size(); ++r) {
    if (arc)
      plane_share[r] =
          std::hypot(limits[r].coefficient(seg.first_axis), limits[r].coefficient(seg.second_axis));
    other_share[r] = std::abs(limits[r].dot(other)) / seg.length;
  }
  double v = 1e300;
  double a = 1e300;
  for (std::size_t r = 0; r < limits.size(); ++r) {
    const double rate = plane_share[r] * in_plane + other_share[r];
    if (rate <= kTiny) continue;
    v = std::min(v, limits[r].max_velocity / rate);
    a = std::min(a, limits[r].max_acceleration / rate);
  }
  const bool linear_motion = direction[0] + direction[1] + direction[2] > kTiny;
  if (linear_motion && config_.max_linear_velocity > 0)
    v = std::min(v, config_.max_linear_velocity);
  if (arc) {
    // In the plane the acceleration is the tangential part (path acceleration x cos b, b the
    // helix angle) plus the centripetal part (in-plane speed^2 / r) at right angles to it.
    // A bound with a share of the plane takes that share of the in-plane acceleration, and
    // of the tangential part (at most the in-plane acceleration / cos b) its other share.
    double plane_a = 1e300;
    for (std::size_t r = 0; r < limits.size(); ++r) {
      if (plane_share[r] <= kTiny) continue;
      plane_a = std::min(plane_a,
                         limits[r].max_acceleration / (plane_share[r] + other_share[r] / in_plane));
    }
    const double fastest = seg.feed > 0 ? std::min(v, seg.feed * config_.max_feed_override) : v;
    double v_plane = v * in_plane;
    double a_plane = 0;
    double radius = seg.radius;
    if (seg.radius_change != 0) {
      // A spiral's point is q e(theta), its angle turning at a rate w in proportion to the
      // path speed and its radius q changing by dq per radian. At a steady path speed the
      // in-plane acceleration is q w^2 inwards plus 2 dq w^2 across the radius, largest at the
      // larger radius; against the largest in-plane speed squared (length's, also at the larger
      // radius) that is the curvature of a circle of `radius`. It is not quite square to the
      // velocity (the cosine between them is at most dq / q), so with the tangential part the
      // plane's limit is shared as if it were lower by the factor sqrt(1 + dq / q).
      const double sweep = std::abs(seg.sweep);
      const double r_max = std::max(seg.radius, seg.radius + seg.radius_change);
      const double r_min = std::min(seg.radius, seg.radius + seg.radius_change);
      const double rate = plane_rate(seg);
      radius = rate * rate / (sweep * std::hypot(sweep * r_max, 2.0 * seg.radius_change));
      const double skew = std::min(1.0, std::abs(seg.radius_change) / (sweep * r_min));
      plane_a /= std::sqrt(1.0 + skew);
    }
    curve_limits(fastest * in_plane, radius, plane_a, kArcNormalShare, v_plane, a_plane);
    a = std::min(a, a_plane / in_plane);
    v = std::min(v, v_plane / in_plane);
  }
  set_directions(seg);
  seg.axis_velocity = v;
  seg.max_velocity = seg.feed > 0 ? std::min(v, seg.feed) : v;
  seg.max_acceleration = a;
}

}  // namespace cncd::motion
