// Blend arcs sized for the speeds they can actually be entered and left at: below its
// curvature's speed limit an arc leaves more of the acceleration to speeding up and slowing
// down, and at every point of every arc each axis stays within its velocity and acceleration
// limits.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Move;
using motion::Segment;

// Plans G64 P`p` lines from `start` through `points` at `feeds` (150 where not given).
std::deque<Segment> plan_path(const config::MachineConfig& config, const AxisPose& start,
                              const std::vector<AxisPose>& points, double p,
                              const std::vector<double>& feeds = {}) {
  motion::Planner planner(config);
  planner.reset(start);
  std::string error;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double feed = k < feeds.size() ? feeds[k] : 150.0;
    Move move = line_to(Move::Kind::feed, points[k][0], points[k][1], points[k][2], feed);
    move.path_mode = Move::PathMode::blend;
    move.tolerance = p;
    EXPECT_TRUE(planner.push(move, true, error)) << error;
  }
  planner.flush();
  return planner.output();
}

// The worst acceleration and velocity of each axis anywhere on `arc` at its speed limit and its
// full tangential acceleration, of either sign, against the axes' limits (largest ratio).
double worst_load(const config::MachineConfig& config, const Segment& arc) {
  const double v = arc.axis_velocity;
  const double a_n = v * v / arc.radius;
  double worst = 0;
  for (int k = 0; k <= 64; ++k) {
    const double phi = arc.sweep * k / 64.0;
    for (int i = 0; i < 3; ++i) {
      const auto& axis = config.axes[static_cast<std::size_t>(i)];
      const double t = -std::sin(phi) * arc.blend_u[i] + std::cos(phi) * arc.blend_v[i];
      const double n = -(std::cos(phi) * arc.blend_u[i] + std::sin(phi) * arc.blend_v[i]);
      worst = std::max(
          worst, (std::abs(arc.max_acceleration * t) + std::abs(a_n * n)) / axis.max_acceleration);
      worst = std::max(worst, std::abs(v * t) / axis.max_velocity);
    }
  }
  return worst;
}

// `length` on from `from` in XY at `degrees` from X.
AxisPose step(const AxisPose& from, double degrees, double length) {
  const double heading = degrees * std::numbers::pi / 180;
  return AxisPose{from[0] + length * std::cos(heading), from[1] + length * std::sin(heading), 0};
}

// The largest share of an axis's acceleration limit that the centripetal part takes anywhere on
// `arc` at its speed limit.
double centripetal_share(const config::MachineConfig& config, const Segment& arc) {
  const double a_n = arc.axis_velocity * arc.axis_velocity / arc.radius;
  double worst = 0;
  for (int k = 0; k <= 64; ++k) {
    const double phi = arc.sweep * k / 64.0;
    for (int i = 0; i < 3; ++i) {
      const double n = std::cos(phi) * arc.blend_u[i] + std::sin(phi) * arc.blend_v[i];
      worst = std::max(
          worst, a_n * std::abs(n) / config.axes[static_cast<std::size_t>(i)].max_acceleration);
    }
  }
  return worst;
}

// Two corners joined by a short line, planned: their blend arcs (each in pieces where the
// speeds at its ends keep it below its top speed) and the line between them.
struct TwoCorners {
  std::vector<Segment> first, second;
  Segment between;
};
TwoCorners two_corners(const config::MachineConfig& config, const std::vector<AxisPose>& points) {
  std::vector<std::vector<Segment>> arcs;
  std::vector<Segment> lines;
  bool in_arc = false;
  for (const auto& seg : plan_path(config, AxisPose{}, points, 0.1)) {
    const bool arc = seg.kind == Segment::Kind::blend;
    if (arc && !in_arc) arcs.emplace_back();
    if (arc) arcs.back().push_back(seg);
    if (!arc) lines.push_back(seg);
    in_arc = arc;
  }
  EXPECT_EQ(arcs.size(), 2u);
  EXPECT_EQ(lines.size(), 3u);
  if (arcs.size() != 2 || lines.size() != 3) return {};
  // The pieces of an arc follow on from one another along one circle.
  for (const auto& pieces : arcs) {
    for (std::size_t k = 1; k < pieces.size(); ++k) {
      EXPECT_EQ(pieces[k].start, pieces[k - 1].end);
      EXPECT_NEAR(pieces[k].radius, pieces[0].radius, 1e-12);
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(pieces[k].blend_center[i], pieces[0].blend_center[i], 1e-12);
    }
  }
  return {arcs[0], arcs[1], lines[1]};
}

// The last blend arc of a path from `start` through `points`.
Segment last_arc(const config::MachineConfig& config, const AxisPose& start,
                 const std::vector<AxisPose>& points) {
  Segment arc;
  for (const auto& seg : plan_path(config, start, points, 0.1))
    if (seg.kind == Segment::Kind::blend) arc = seg;
  return arc;
}

// `soft`, a gentle corner's arc with a sharp corner's slow arc `sharp` at the other end of the
// short line `between`, against `top`, the same corner sized for its top speed.
void expect_sized_for_neighbour(const config::MachineConfig& config, const Segment& soft,
                                const Segment& top, const Segment& sharp, const Segment& between) {
  EXPECT_NEAR(top.radius, soft.radius, 1e-9);
  // At its top speed the centripetal part takes 0.98 of what the axes allow, or as much as
  // leaves the tangential part 0.05 of the plane's smallest limit (2000).
  const double share = centripetal_share(config, top);
  EXPECT_LE(share, 0.98 + 1e-4);
  EXPECT_TRUE(share > 0.98 - 1e-4 || std::abs(top.max_acceleration - 0.05 * 2000) < 1e-6)
      << share << " " << top.max_acceleration;
  // Between the sharp corner and the arc the speed changes by at most sqrt(v_sharp^2 + 2 a L):
  // the arc keeps a speed limit at least that high (plus its own speeding up or slowing down)
  // and gets much more of the acceleration along the path.
  const double reach = std::sqrt(sharp.axis_velocity * sharp.axis_velocity +
                                 2 * between.max_acceleration * between.length);
  EXPECT_LT(soft.axis_velocity, top.axis_velocity);
  EXPECT_GE(soft.axis_velocity, std::sqrt(reach * reach + 2 * soft.max_acceleration * soft.length));
  EXPECT_GT(soft.max_acceleration, 1.5 * top.max_acceleration);
  EXPECT_LE(worst_load(config, soft), 1 + 1e-9);
  EXPECT_LE(worst_load(config, top), 1 + 1e-9);
}

// A sharp corner (slow, tight blend), a short line, then a gentle corner whose curvature alone
// would allow far more speed than the short line can reach from the sharp corner.
TEST(BlendLoad, AnArcEnteredBelowItsTopSpeedGetsMoreTangentialAcceleration) {
  const auto config = small_mill();
  const AxisPose a{10, 0, 0};
  const AxisPose b = step(a, 120, 2);  // 120 degrees at a, then 20 at b
  const auto corners = two_corners(config, {a, b, step(b, 140, 10)});
  ASSERT_FALSE(corners.second.empty());
  // The same gentle corner at the end of the same 2 mm line, entered straight on from further
  // back (no corner before it): the arc sized for its top speed.
  const Segment top = last_arc(config, step(b, 120, -40), {step(b, 120, -2), b, step(b, 140, 10)});
  expect_sized_for_neighbour(config, corners.second.front(), top, corners.first.back(),
                             corners.between);
  // The arc's slow end, near the sharp corner, is sized for a lower speed than its fast end
  // (its centripetal part takes less, the part along the path more).
  ASSERT_EQ(corners.second.size(), 4u);
  EXPECT_LT(corners.second.front().axis_velocity, corners.second.back().axis_velocity);
}

// A gentle corner, a short line, then a sharp corner: the gentle corner's arc can be left no
// faster than the short line lets the path slow down to the sharp one's speed, far below what
// its curvature alone would allow.
TEST(BlendLoad, AnArcLeftBelowItsTopSpeedGetsMoreTangentialAcceleration) {
  const auto config = small_mill();
  const AxisPose b{50, 0, 0};
  const AxisPose c = step(b, 20, 2.3);  // 20 degrees at b, then 120 at c
  const auto corners = two_corners(config, {b, c, step(c, 140, 10)});
  // The same gentle corner followed by a long straight line: sized for its top speed.
  ASSERT_FALSE(corners.first.empty());
  const Segment top = last_arc(config, AxisPose{}, {b, step(b, 20, 50)});
  expect_sized_for_neighbour(config, corners.first.back(), top, corners.second.front(),
                             corners.between);
  ASSERT_EQ(corners.first.size(), 4u);
  EXPECT_LT(corners.first.back().axis_velocity, corners.first.front().axis_velocity);
}

// Under S-curve profiles a speed limit just above the speeds the path reaches still costs time
// (the acceleration eases off before it): the gentle corner's arc before the sharp one keeps its
// top limits, and at its top the centripetal part takes 0.95 of the plane's smallest limit.
TEST(BlendLoad, UnderAJerkLimitAnArcKeepsItsTopLimits) {
  auto config = small_mill();
  config.scurve = true;
  config.max_linear_jerk = 40000;
  const AxisPose b{50, 0, 0};
  const AxisPose c = step(b, 20, 2.3);
  const auto corners = two_corners(config, {b, c, step(c, 140, 10)});
  ASSERT_EQ(corners.first.size(), 1u);
  const Segment top = last_arc(config, AxisPose{}, {b, step(b, 20, 50)});
  EXPECT_DOUBLE_EQ(corners.first[0].axis_velocity, top.axis_velocity);
  EXPECT_DOUBLE_EQ(corners.first[0].max_acceleration, top.max_acceleration);
  EXPECT_NEAR(top.axis_velocity, std::sqrt(0.95 * 2000 * top.radius), 1e-9);
  EXPECT_GE(top.max_acceleration, std::sqrt(1 - 0.95 * 0.95) * 2000 * (1 - 1e-12));
  EXPECT_LE(worst_load(config, top), 1 + 1e-9);
}

// A corner in the YZ plane, the path climbing along Z and turning by 50 degrees about it: along
// the arc the tangent lies mostly along Z (1000 mm/s^2) and the normal mostly along Y (2000).
// Each axis is held to its limit at every point of the sweep, not the plane to its smallest:
// the centripetal part takes 0.98 of what Y allows where the normal lies along Y, and the arc
// runs sqrt(2) times faster than sqrt(0.98 x 1000 r), Z keeping more than 0.1 of its limit
// for speeding up and slowing down.
TEST(BlendLoad, AnArcHoldsEachAxisToItsOwnLimit) {
  const auto config = small_mill();
  const double tilt = 25 * std::numbers::pi / 180;
  const AxisPose b{0, -20 * std::sin(tilt), 20 * std::cos(tilt)};
  const AxisPose c{0, b[1] + 20 * std::sin(tilt), b[2] + 20 * std::cos(tilt)};
  const Segment arc = last_arc(config, AxisPose{}, {b, c});
  ASSERT_GT(arc.radius, 0.5);
  EXPECT_NEAR(centripetal_share(config, arc), 0.98, 1e-4);
  EXPECT_NEAR(arc.axis_velocity, std::sqrt(0.98 * 2000 * arc.radius), 1e-9);
  EXPECT_GT(arc.axis_velocity, 1.4 * std::sqrt(0.98 * 1000 * arc.radius));
  EXPECT_GT(arc.max_acceleration, 0.1 * 1000);
  EXPECT_LE(worst_load(config, arc), 1 + 1e-9);
  EXPECT_GT(worst_load(config, arc), 0.999);
}

// Random dense 3D paths of short lines with small and large turns, random feeds and
// tolerances: every blend arc, at its speed limit with its full tangential acceleration of
// either sign, keeps every axis within its velocity and acceleration limits, and brings one
// of them to its limit somewhere.
TEST(BlendLoad, RandomDensePathsKeepEveryAxisWithinItsLimitsOnTheArcs) {
  const auto config = small_mill();
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> unit(0, 1);
  int arcs = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<AxisPose> points;
    std::vector<double> feeds;
    AxisPose p{};
    double heading = unit(rng) * 2 * std::numbers::pi;
    double climb = (unit(rng) - 0.5) * 0.6;
    for (int k = 0; k < 60; ++k) {
      const double turn =
          (unit(rng) < 0.2 ? 40 + 80 * unit(rng) : 3 + 27 * unit(rng)) * std::numbers::pi / 180;
      heading += unit(rng) < 0.5 ? turn : -turn;
      climb = std::clamp(climb + (unit(rng) - 0.5) * 0.4, -0.8, 0.8);
      const double length = 0.3 + 6 * unit(rng);
      p[0] += length * std::cos(climb) * std::cos(heading);
      p[1] += length * std::cos(climb) * std::sin(heading);
      p[2] += length * std::sin(climb);
      points.push_back(p);
      feeds.push_back(20 + 200 * unit(rng));
    }
    const double tolerance = 0.01 + 0.2 * unit(rng);
    const auto planned = plan_path(config, AxisPose{}, points, tolerance, feeds);
    // Every programmed move counted once, arcs in pieces or not, and the path continuous.
    std::uint32_t moves = 0;
    for (std::size_t k = 0; k < planned.size(); ++k) {
      moves += planned[k].moves;
      for (int i = 0; k > 0 && i < 3; ++i)
        EXPECT_NEAR(planned[k].start[i], planned[k - 1].end[i], 1e-9) << "trial " << trial;
    }
    EXPECT_EQ(moves, points.size()) << "trial " << trial;
    for (const auto& seg : planned) {
      if (seg.kind != Segment::Kind::blend) continue;
      ++arcs;
      // Within the limits, and at them on some axis somewhere: each arc takes all its sweep
      // allows.
      const double load = worst_load(config, seg);
      EXPECT_LE(load, 1 + 1e-9) << "trial " << trial;
      EXPECT_GT(load, 0.999) << "trial " << trial;
      EXPECT_LE(seg.max_velocity, seg.axis_velocity);
    }
  }
  EXPECT_GT(arcs, 1000);
}

}  // namespace
}  // namespace cncd::test
