#include "path_reference.hpp"

#include "reference_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>

namespace cncd::bench {
namespace {

using motion::AxisPose;
using motion::kAxes;
using motion::Segment;
using reference::Curve;
using reference::Grid;
using reference::kInf;
using reference::kTiny;
// The planner's: junctions within 1e-6 rad are tangent, and smaller blend arcs stop instead.
constexpr double kTangentCos = 1.0 - 5e-13;
constexpr double kMinBlendRadius = 1e-6;

Curve arc_curve(const Segment& arc) {
  Curve curve;
  const double length = arc.length;
  for (int i = 0; i < kAxes; ++i) {
    curve.center[i] = arc.start[i];
    curve.lin[i] = (arc.end[i] - arc.start[i]) / length;
  }
  for (int axis : {static_cast<int>(arc.first_axis), static_cast<int>(arc.second_axis)}) {
    curve.center[axis] = axis == arc.first_axis ? arc.center_first : arc.center_second;
    curve.lin[axis] = 0;
  }
  curve.u[arc.first_axis] = 1;
  curve.v[arc.second_axis] = 1;
  curve.r0 = arc.radius;
  curve.dr = arc.radius_change / length;
  curve.th0 = arc.start_angle;
  curve.w = arc.sweep / length;
  return curve;
}

AxisPose unit(AxisPose d) {
  const double norm = std::sqrt(std::inner_product(d.begin(), d.end(), d.begin(), 0.0));
  if (norm > kTiny) {
    for (double& x : d)
      x /= norm;
  } else {
    d.fill(0.0);
  }
  return d;
}

// Unit tangents (over all axes) at the start and the end of a line or an arc.
void directions(const Segment& move, AxisPose& start, AxisPose& end) {
  if (move.kind != Segment::Kind::arc) {
    for (int i = 0; i < kAxes; ++i)
      start[i] = move.end[i] - move.start[i];
    end = start = unit(start);
    return;
  }
  const Curve curve = arc_curve(move);
  AxisPose c{};
  curve.at(0, start, c);
  curve.at(move.length, end, c);
  start = unit(start);
  end = unit(end);
}

bool moving(const Segment& move) {
  return move.kind != Segment::Kind::dwell && move.length > 0;
}

// A line whose path length is its length over all axes (as the planner blends only those).
bool euclidean(const Segment& s) {
  double sum = 0;
  for (int i = 0; i < kAxes; ++i)
    sum += (s.end[i] - s.start[i]) * (s.end[i] - s.start[i]);
  return s.kind == Segment::Kind::line &&
         std::abs(std::sqrt(sum) - s.length) <= 1e-9 * std::max(1.0, s.length);
}

// How two consecutive moves join.
struct Join {
  bool tangent = false;
  bool blend = false;
  double reach = 0;  // blend: from the corner along each line
  Curve arc;
  double length = 0, turn = 0, feed = 0;
};

Join join(const Segment& prev, const Segment& next, const ReferenceOptions& options) {
  Join j;
  AxisPose d1{}, d2{}, ignore{};
  directions(prev, ignore, d1);
  directions(next, d2, ignore);
  double c = 0;
  for (int i = 0; i < kAxes; ++i)
    c += d1[i] * d2[i];
  j.tangent = c > kTangentCos;
  if (j.tangent || !options.blend_corners || !euclidean(prev) || !euclidean(next)) return j;
  // The arc of radius r touches both lines r tan(turn / 2) from the corner, at most half of
  // each, and passes r (1 / cos(turn / 2) - 1) from the corner, within P for r up to
  // P cos(turn / 2) / (1 - cos(turn / 2)) (1 - cos x = 2 sin^2(x / 2)): the planner's blend.
  const double turn = std::acos(std::clamp(c, -1.0, 1.0));
  const double tan_half = std::tan(0.5 * turn);
  double radius = 0.5 * std::min(prev.length, next.length) / tan_half;
  if (options.tolerance > 0) {
    const double q = std::sin(0.25 * turn);
    radius = std::min(radius, options.tolerance * std::cos(0.5 * turn) / (2 * q * q));
  }
  if (!(radius >= kMinBlendRadius) || !std::isfinite(radius)) return j;
  const double reach = radius * tan_half;
  AxisPose u{};
  for (int i = 0; i < kAxes; ++i)
    u[i] = -(d2[i] - c * d1[i]);
  u = unit(u);
  for (int i = 0; i < kAxes; ++i)
    j.arc.center[i] = prev.end[i] - reach * d1[i] - radius * u[i];
  j.arc.u = u;
  j.arc.v = d1;
  j.arc.r0 = radius;
  j.arc.w = 1 / radius;
  j.blend = true;
  j.reach = reach;
  j.length = radius * turn;
  j.turn = turn;
  j.feed = prev.feed > 0 && next.feed > 0 ? std::min(prev.feed, next.feed)
                                          : std::max(prev.feed, next.feed);
  return j;
}

}  // namespace

namespace {

bool mergeable(const Segment& s) {
  return s.kind == Segment::Kind::line && s.feed > 0 && s.length > 0 && euclidean(s);
}

// Whether every point of `skipped` lies within q of the line from `from` to `to`, in order
// along it.
bool within(const AxisPose& from, const AxisPose& to, const std::vector<AxisPose>& skipped,
            double q) {
  AxisPose d{};
  double len_sq = 0;
  for (int i = 0; i < kAxes; ++i) {
    d[i] = to[i] - from[i];
    len_sq += d[i] * d[i];
  }
  if (len_sq <= 0) return false;
  double last_t = 0;
  for (const AxisPose& p : skipped) {
    double t = 0;
    for (int i = 0; i < kAxes; ++i)
      t += (p[i] - from[i]) * d[i];
    t /= len_sq;
    if (t < last_t || t > 1) return false;
    last_t = t;
    double off = 0;
    for (int i = 0; i < kAxes; ++i)
      off += (p[i] - from[i] - t * d[i]) * (p[i] - from[i] - t * d[i]);
    if (off > q * q) return false;
  }
  return true;
}

// The path and what each of its moves completes, after merging (time_optimal()).
void solve(const config::MachineConfig& machine, const std::vector<Segment>& moves,
           const std::vector<std::size_t>& last, const ReferenceOptions& options,
           PathReference& out) {
  Grid grid(machine, options);
  bool after = false;  // a moving move came before, with no dwell since
  std::size_t prev = 0;
  std::vector<Join> joins(moves.size());
  for (std::size_t i = 0; i < moves.size(); ++i) {
    if (moves[i].kind == Segment::Kind::dwell) {
      after = false;
    } else if (moving(moves[i])) {
      if (after) joins[i] = join(moves[prev], moves[i], options);
      after = true;
      prev = i;
    }
  }
  after = false;
  // The move whose line the blends at its ends used up entirely (the planner then counts it
  // done at the end of the blend that follows), or none.
  std::size_t used_up = moves.size();
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const Segment& move = moves[i];
    const auto index = static_cast<std::uint32_t>(last[i]);
    if (move.kind == Segment::Kind::dwell) {
      out.move_s[last[i]] += move.dwell_s;
      grid.stop();
      after = false;
      continue;
    }
    if (!moving(move)) continue;
    const Join& j = joins[i];
    double trim = 0;  // what the blend into it takes of its start
    if (after && j.blend) {
      const std::size_t owner = used_up < moves.size() ? last[used_up] : last[i];
      grid.curve(j.arc, j.length, j.turn, j.feed, static_cast<std::uint32_t>(owner));
      trim = j.reach;
      ++out.blends;
    } else if (after && !j.tangent) {
      grid.stop();
      ++out.stops;
    }
    // The next move's blend takes the end of this one.
    double end_trim = 0;
    for (std::size_t k = i + 1; k < moves.size() && moves[k].kind != Segment::Kind::dwell; ++k) {
      if (!moving(moves[k])) continue;
      if (joins[k].blend) end_trim = joins[k].reach;
      break;
    }
    used_up = moves.size();
    if (move.kind == Segment::Kind::arc) {
      grid.curve(arc_curve(move), move.length, move.sweep, move.feed, index);
    } else {
      const double left = move.length - trim - end_trim;
      grid.line(move, left, index);
      if (left <= 1e-12) used_up = i;
    }
    after = true;
  }
  out.steps = grid.solve(out.move_s);
  if (options.profile) out.profile = grid.profile();
}

}  // namespace

std::vector<Segment> merged_path(const std::vector<Segment>& moves, double q,
                                 std::vector<std::size_t>& last) {
  constexpr std::size_t kMaxMerged = 256;  // the planner's
  std::vector<Segment> path;
  last.clear();
  for (std::size_t i = 0; i < moves.size();) {
    Segment run = moves[i];
    std::size_t end = i;
    if (q > 0 && mergeable(run)) {
      std::vector<AxisPose> skipped;
      for (std::size_t k = i + 1; k < moves.size() && skipped.size() < kMaxMerged; ++k) {
        if (!mergeable(moves[k]) || moves[k].feed != run.feed) break;
        skipped.push_back(run.end);
        if (!within(run.start, moves[k].end, skipped, q)) break;
        run.end = moves[k].end;
        end = k;
      }
      double sum = 0;
      for (int a = 0; a < kAxes; ++a)
        sum += (run.end[a] - run.start[a]) * (run.end[a] - run.start[a]);
      run.length = std::sqrt(sum);
    }
    path.push_back(run);
    last.push_back(end);
    i = end + 1;
  }
  return path;
}

PathReference time_optimal(const config::MachineConfig& machine,
                           const std::vector<motion::Segment>& moves,
                           const ReferenceOptions& options) {
  PathReference out;
  out.move_s.assign(moves.size(), 0.0);
  std::vector<std::size_t> last;
  const double q = options.blend_corners ? options.merge_tolerance : 0.0;
  const std::vector<Segment> path = merged_path(moves, q, last);
  solve(machine, path, last, options, out);
  for (double s : out.move_s)
    out.time_s += s;
  return out;
}

namespace {

// The highest speed squared on a blend arc at which every axis takes its share of the
// centripetal acceleration, at its largest over the arc, within its own limit (and within its
// velocity and the feed).
double blend_cap(const config::MachineConfig& machine, const Segment& blend) {
  constexpr int kSamples = 16;
  double x = blend.feed > 0 ? blend.feed * blend.feed : kInf;
  for (int i = 0; i < kAxes; ++i) {
    const auto& axis = machine.axes[static_cast<std::size_t>(i)];
    if (!axis.present) continue;
    double normal = 0, tangent = 0;
    for (int k = 0; k <= kSamples; ++k) {
      const double phi = blend.sweep * k / kSamples;
      normal = std::max(
          normal, std::abs(std::cos(phi) * blend.blend_u[i] + std::sin(phi) * blend.blend_v[i]));
      tangent = std::max(
          tangent, std::abs(-std::sin(phi) * blend.blend_u[i] + std::cos(phi) * blend.blend_v[i]));
    }
    if (normal > kTiny) x = std::min(x, axis.max_acceleration * blend.radius / normal);
    if (tangent > kTiny) x = std::min(x, std::pow(axis.max_velocity / tangent, 2));
  }
  return x;
}

}  // namespace

PathReference planned_optimal(const config::MachineConfig& machine,
                              const std::vector<motion::Segment>& planned, std::size_t moves,
                              bool axis_blend_speeds) {
  PathReference out;
  out.move_s.assign(moves, 0.0);
  Grid grid(machine, ReferenceOptions{});
  std::size_t done = 0;   // programmed moves complete before the current segment
  bool piece_of = false;  // the segment before was a blend arc
  const Segment* previous = nullptr;
  for (const Segment& seg : planned) {
    const auto index = static_cast<std::uint32_t>(std::min(done, moves - 1));
    if (seg.kind == Segment::Kind::dwell) {
      out.move_s[index] += seg.dwell_s;
      grid.stop();
    } else {
      const double v = seg.max_velocity;
      const bool blend = seg.kind == Segment::Kind::blend;
      grid.fixed(seg.length, blend && axis_blend_speeds ? blend_cap(machine, seg) : v * v,
                 seg.max_acceleration, index);
      if (!seg.continuous) {
        grid.stop();
        ++out.stops;
      } else {
        grid.limit(seg.junction_velocity * seg.junction_velocity);
      }
      // An arc the planner runs in pieces (each sized for its own speeds) is one blend.
      if (blend && !(piece_of && previous->blend_center == seg.blend_center &&
                     previous->radius == seg.radius))
        ++out.blends;
      piece_of = blend;
      previous = &seg;
    }
    done += seg.moves;
  }
  out.steps = grid.solve(out.move_s);
  for (double s : out.move_s)
    out.time_s += s;
  return out;
}

}  // namespace cncd::bench
