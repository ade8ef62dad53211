// G64 fillets at corners where a programmed arc meets a line or another arc in its plane: a
// circular arc of radius r tangent to both curves. Its centre lies on both curves moved by r
// towards the inside of the corner (a line shifted sideways, a circle grown or shrunk by r);
// r is the largest that stays within P of the corner and takes at most half of each move.
// The programmed arcs are trimmed by their start or end angle.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "cncd/motion/planner.hpp"

namespace cncd::motion {
namespace {

constexpr double kPi = std::numbers::pi;
// Smaller fillets are not worth a segment: the corner is left to the kink rule or stops.
constexpr double kMinFilletRadius = 1e-6;
// The fillet leaves along the next curve within this angle (rad): at full speed the step in
// velocity is far below what an axis gains in a period.
constexpr double kTangentSin = 1e-7;

struct Vec {
  double x = 0, y = 0;
};
Vec operator+(Vec a, Vec b) {
  return {a.x + b.x, a.y + b.y};
}
Vec operator-(Vec a, Vec b) {
  return {a.x - b.x, a.y - b.y};
}
Vec operator*(double k, Vec a) {
  return {k * a.x, k * a.y};
}
double dot(Vec a, Vec b) {
  return a.x * b.x + a.y * b.y;
}
double cross(Vec a, Vec b) {
  return a.x * b.y - a.y * b.x;
}
double norm(Vec a) {
  return std::hypot(a.x, a.y);
}
Vec left(Vec a) {
  return {-a.y, a.x};
}  // turned a quarter counter-clockwise

// An angle brought into [0, 2 pi).
double wrap(double angle) {
  angle = std::fmod(angle, 2 * kPi);
  return angle < 0 ? angle + 2 * kPi : angle;
}

// One curve at the corner, in the plane, with the corner at the origin.
struct Side {
  bool arc = false;
  Vec dir;     // unit tangent at the corner, along the travel
  Vec center;  // arc
  double radius = 0;
  double turn = 0;   // arc: +1 counter-clockwise, -1 clockwise
  double limit = 0;  // longest path length the fillet may take from the move
};

struct Fit {
  Vec center;            // of the fillet
  Vec from, to;          // where it leaves the first curve and joins the second
  Vec from_dir, to_dir;  // unit tangents there
  double trim_in = 0;    // path length taken from each move
  double trim_out = 0;
  double angle_in = 0;  // an arc side's trimmed angle (rad, > 0)
  double angle_out = 0;
  double sweep = 0;  // of the fillet (rad, > 0)
};

// The foot of the fillet centre `f` on a side, the path length between it and the corner
// (`before`: the foot comes before the corner) and the tangent there. False when the foot is
// on the wrong side of the corner or more than half a turn of the arc away.
bool foot(const Side& side, Vec f, double r, double sigma, bool before, Vec& at, double& trim,
          double& angle, Vec& dir) {
  if (!side.arc) {
    at = f - r * (sigma * left(side.dir));
    trim = before ? -dot(at, side.dir) : dot(at, side.dir);
    dir = side.dir;
    angle = 0;
    return trim > 0;
  }
  const Vec radial = f - side.center;
  const double length = norm(radial);
  if (!(length > 0)) return false;
  const Vec unit = (1.0 / length) * radial;
  at = side.center + side.radius * unit;
  const double a_foot = std::atan2(unit.y, unit.x);
  const double a_corner = std::atan2(-side.center.y, -side.center.x);
  angle = wrap(side.turn * (before ? a_corner - a_foot : a_foot - a_corner));
  trim = side.radius * angle;
  dir = side.turn * left(unit);
  return angle > 0 && angle < kPi;
}

// Where the centre of a fillet of radius r lies: on both offset curves, the intersection
// nearest the corner that gives a proper fillet.
std::optional<Fit> fit(const Side& in, const Side& out, double sigma, double r, double tolerance) {
  // A circle's offset towards the corner's inside: shrunk when the arc bends that way.
  auto offset = [&](const Side& s) { return s.radius - s.turn * sigma * r; };
  Vec candidates[2];
  int count = 0;
  if (in.arc && out.arc) {
    const double r1 = offset(in), r2 = offset(out);
    const Vec d = out.center - in.center;
    const double dd = norm(d);
    if (!(r1 > 0) || !(r2 > 0) || !(dd > 0)) return std::nullopt;
    const double x = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd);
    const double h2 = r1 * r1 - x * x;
    if (h2 < 0) return std::nullopt;
    const Vec axis = (1.0 / dd) * d;
    const Vec base = in.center + x * axis;
    const double h = std::sqrt(h2);
    candidates[count++] = base + h * left(axis);
    candidates[count++] = base - h * left(axis);
  } else {
    // The centre is r from the line, t along it from the corner: |r n + t d - O| = rho, with
    // |O| ~ R expanded so that no large terms cancel.
    const Side& line = in.arc ? out : in;
    const Side& arc = in.arc ? in : out;
    const double rho = offset(arc);
    if (!(rho > 0)) return std::nullopt;
    const Vec n = sigma * left(line.dir);
    const double b = -dot(arc.center, line.dir);
    const double c = (norm(arc.center) - arc.radius) * (norm(arc.center) + arc.radius) +
                     2 * r * (arc.turn * sigma * arc.radius - dot(n, arc.center));
    const double disc = b * b - c;
    if (disc < 0) return std::nullopt;
    const double root = std::sqrt(disc);
    for (const double t : {-b + root, -b - root})
      candidates[count++] = r * n + t * line.dir;
  }
  std::optional<Fit> best;
  for (int k = 0; k < count; ++k) {
    Fit f;
    f.center = candidates[k];
    if (best && norm(f.center) >= norm(best->center)) continue;
    if (!foot(in, f.center, r, sigma, true, f.from, f.trim_in, f.angle_in, f.from_dir) ||
        !foot(out, f.center, r, sigma, false, f.to, f.trim_out, f.angle_out, f.to_dir))
      continue;
    if (f.trim_in > in.limit || f.trim_out > out.limit) continue;
    // Within P of the corner: the fillet's circle passes |centre| - r from it.
    if (tolerance > 0 && norm(f.center) - r > tolerance) continue;
    const Vec u = (1.0 / r) * (f.from - f.center);
    const Vec w = (1.0 / r) * (f.to - f.center);
    f.sweep = std::atan2(dot(w, f.from_dir), dot(w, u));
    if (!(f.sweep > 0)) continue;
    const Vec end_dir = -std::sin(f.sweep) * u + std::cos(f.sweep) * f.from_dir;
    if (std::abs(cross(end_dir, f.to_dir)) > kTangentSin || dot(end_dir, f.to_dir) <= 0) continue;
    best = f;
  }
  return best;
}

// The largest fillet radius that fits (grown by factors of 4, then bisected to a millionth),
// at most 1000 times the path length it may take from both moves. Where an arc curves back
// towards the line it kinks away from, every radius fits and the fillet tends to a straight
// line: the cap keeps its centre near enough for its points to be exact to far below a
// micrometre (and a radius that large no longer limits the speed).
std::optional<std::pair<double, Fit>> largest_fit(const Side& in, const Side& out, double sigma,
                                                  double tolerance) {
  const double cap = 1e3 * (in.limit + out.limit);
  std::optional<std::pair<double, Fit>> best;
  double lo = 0, hi = 0;
  for (double r = kMinFilletRadius; r <= cap; r = r < cap && 4 * r > cap ? cap : 4 * r) {
    const auto f = fit(in, out, sigma, r, tolerance);
    if (!f) {
      hi = r;
      break;
    }
    lo = r;
    best = {r, *f};
  }
  if (!best || hi == 0) return best;
  for (int k = 0; k < 60 && hi - lo > 1e-6 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (const auto f = fit(in, out, sigma, mid, tolerance)) {
      lo = mid;
      best = {mid, *f};
    } else {
      hi = mid;
    }
  }
  return best;
}

// Whether a line or an arc moves only the plane's two axes (an arc without a helix), with its
// path length measured in that plane.
bool planar(const Segment& s, int first, int second) {
  for (int i = 0; i < kAxes; ++i) {
    if (i != first && i != second && std::abs(s.end[i] - s.start[i]) > 1e-12) return false;
  }
  if (s.kind == Segment::Kind::arc) return s.first_axis == first && s.second_axis == second;
  const double plane = std::hypot(s.end[first] - s.start[first], s.end[second] - s.start[second]);
  return s.kind == Segment::Kind::line &&
         std::abs(plane - s.length) <= 1e-9 * std::max(1.0, s.length);
}

Side side_of(const Segment& s, const AxisPose& corner, bool incoming, int first, int second,
             double limit) {
  Side side;
  const AxisPose& d = incoming ? s.end_direction : s.start_direction;
  side.dir = {d[first], d[second]};
  side.dir = (1.0 / norm(side.dir)) * side.dir;
  side.limit = limit;
  if (s.kind == Segment::Kind::arc) {
    side.arc = true;
    side.center = {s.center_first - corner[first], s.center_second - corner[second]};
    side.radius = s.radius;
    side.turn = s.sweep > 0 ? 1.0 : -1.0;
  }
  return side;
}

}  // namespace

bool Planner::fillet(Held& held, Segment& next) {
  Segment& prev = held.segment;
  const Segment& arc = prev.kind == Segment::Kind::arc ? prev : next;
  if (arc.kind != Segment::Kind::arc) return false;
  // The fit is made for circles: a spiral's end (a radius that changes along the sweep) is
  // left to the kink rule, or stops.
  if (prev.radius_change != 0 || next.radius_change != 0) return false;
  const int first = arc.first_axis, second = arc.second_axis;
  if (!planar(prev, first, second) || !planar(next, first, second)) return false;
  const AxisPose corner = prev.end;
  const Side in =
      side_of(prev, corner, true, first, second, std::min(0.5 * held.full_length, prev.length));
  const Side out = side_of(next, corner, false, first, second, 0.5 * next.length);
  const double turn = cross(in.dir, out.dir);
  if (std::abs(turn) < 1e-12) return false;  // straight on or a reversal
  const double sigma = turn > 0 ? 1.0 : -1.0;
  const auto found = largest_fit(in, out, sigma, held.tolerance);
  if (!found) return false;
  const double r = found->first;
  const Fit& f = found->second;

  auto place = [&](Vec p) {
    AxisPose q = corner;
    q[first] += p.x;
    q[second] += p.y;
    return q;
  };
  auto along = [&](Vec p) {
    AxisPose q{};
    q[first] = p.x;
    q[second] = p.y;
    return q;
  };
  Segment blend;
  blend.kind = Segment::Kind::blend;
  blend.start = place(f.from);
  blend.end = place(f.to);
  blend.blend_center = place(f.center);
  blend.blend_u = along((1.0 / r) * (f.from - f.center));
  blend.blend_v = along(f.from_dir);
  blend.radius = r;
  blend.sweep = f.sweep;
  blend.length = r * f.sweep;
  blend.start_direction = along(f.from_dir);
  blend.end_direction = along(f.to_dir);
  blend.first_axis = static_cast<std::int8_t>(first);
  blend.second_axis = static_cast<std::int8_t>(second);
  blend.fillet = true;
  blend.corner_first = corner[first];
  blend.corner_second = corner[second];
  if (in.arc) {
    blend.in_center_first = prev.center_first;
    blend.in_center_second = prev.center_second;
    blend.in_radius = prev.radius;
  }
  if (out.arc) {
    blend.out_center_first = next.center_first;
    blend.out_center_second = next.center_second;
    blend.out_radius = next.radius;
  }
  blend.line = next.line;
  blend.moves = 0;
  blend.continuous = true;
  blend.feed = prev.feed > 0 && next.feed > 0 ? std::min(prev.feed, next.feed)
                                              : std::max(prev.feed, next.feed);
  set_blend_limits(blend);
  // A fillet that must be crossed this slowly is no better than a stop.
  if (!(blend.axis_velocity > 0.01 * std::min(prev.max_velocity, next.max_velocity))) return false;
  // Its extremes on each axis (the ends, or where it runs square to the axis) within the
  // soft limits.
  for (const int axis : {first, second}) {
    const auto& limits = config_.axes[static_cast<std::size_t>(axis)];
    if (!limits.present) continue;
    const double peak = std::atan2(blend.blend_v[axis], blend.blend_u[axis]);
    double low = std::min(blend.start[axis], blend.end[axis]);
    double high = std::max(blend.start[axis], blend.end[axis]);
    if (wrap(peak) <= f.sweep) high = blend.blend_center[axis] + r;
    if (wrap(peak + kPi) <= f.sweep) low = blend.blend_center[axis] - r;
    if (low < limits.min_limit - 1e-9 || high > limits.max_limit + 1e-9) return false;
  }

  if (in.arc) {
    prev.sweep -= in.turn * f.angle_in;
    prev.length = prev.radius * std::abs(prev.sweep);
    prev.end = blend.start;
    set_limits(prev);
    if (held.reserved) reserve_for_kink(prev);
  } else {
    prev.end = blend.start;
    prev.length -= f.trim_in;
  }
  if (out.arc) {
    next.start_angle += out.turn * f.angle_out;
    next.sweep -= out.turn * f.angle_out;
    next.length = next.radius * std::abs(next.sweep);
    next.start = blend.end;
    set_limits(next);
  } else {
    next.start = blend.end;
    next.length -= f.trim_out;
  }
  prev.continuous = true;
  emit_corner(prev, held.entry_speed, blend, next);
  return true;
}

}  // namespace cncd::motion
