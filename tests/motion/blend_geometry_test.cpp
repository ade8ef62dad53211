// The planner's blend arcs, checked on their geometry: tangent to both lines, within P of the
// corner (exactly P when the lines are long), at most half of each line, in any plane.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Move;
using motion::Segment;

double distance(const AxisPose& a, const AxisPose& b) {
  double sum = 0;
  for (int i = 0; i < motion::kAxes; ++i)
    sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum);
}

// Plans `a` then `b` from the origin in G64 P`p` and returns the planner's segments.
std::deque<Segment> corner(const AxisPose& a, const AxisPose& b, double p) {
  static const auto config = small_mill();
  motion::Planner planner(config);
  planner.reset(AxisPose{});
  std::string error;
  for (const auto& end : {a, b}) {
    Move move = line_to(Move::Kind::feed, end[0], end[1], end[2], 100);
    move.path_mode = Move::PathMode::blend;
    move.tolerance = p;
    EXPECT_TRUE(planner.push(move, true, error)) << error;
  }
  planner.flush();
  return planner.output();
}

TEST(BlendGeometry, ArcIsTangentAndPassesPFromTheCorner) {
  // A corner in a tilted plane over X, Y and Z, turning by about 100 degrees.
  const AxisPose a{10, 5, 4, 0, 0, 0, 0, 0, 0};
  const AxisPose b{6, 14, -3, 0, 0, 0, 0, 0, 0};
  const auto out = corner(a, b, 0.2);
  ASSERT_EQ(out.size(), 3u);
  const Segment& blend = out[1];
  ASSERT_EQ(blend.kind, Segment::Kind::blend);
  EXPECT_EQ(out[0].end, blend.start);
  EXPECT_EQ(blend.end, out[2].start);
  EXPECT_EQ(out[2].end, b);
  EXPECT_TRUE(out[0].continuous && blend.continuous && !out[2].continuous);
  EXPECT_EQ(out[0].moves + blend.moves + out[2].moves, 2u);
  // Tangent: the arc's ends leave along the lines, the centre is R from every point.
  const double h = 1e-6 * blend.length;
  const AxisPose p0 = blend.point_at(0), p1 = blend.point_at(h);
  const AxisPose q0 = blend.point_at(blend.length - h), q1 = blend.point_at(blend.length);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((p1[i] - p0[i]) / h, out[0].end_direction[i], 1e-6);
    EXPECT_NEAR((q1[i] - q0[i]) / h, out[2].start_direction[i], 1e-6);
  }
  double closest = 1e9;
  for (int k = 0; k <= 1000; ++k) {
    const AxisPose p = blend.point_at(blend.length * k / 1000);
    EXPECT_NEAR(distance(p, blend.blend_center), blend.radius, 1e-9);
    closest = std::min(closest, distance(p, a));
  }
  // The lines are long: the tolerance, not the half-line rule, sets the size.
  EXPECT_NEAR(closest, 0.2, 1e-6);
  EXPECT_NEAR(distance(blend.start, a), distance(blend.end, a), 1e-9);
}

TEST(BlendGeometry, BlendsUseAtMostHalfOfEachLineAndPZeroUsesAllOfThat) {
  // 90 degrees between a 2 mm and a 10 mm line: P0 takes half of the short one.
  auto out = corner({2, 0, 0, 0, 0, 0, 0, 0, 0}, {2, 10, 0, 0, 0, 0, 0, 0, 0}, 0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(distance(out[1].start, {2, 0, 0, 0, 0, 0, 0, 0, 0}), 1.0, 1e-12);
  EXPECT_NEAR(out[1].radius, 1.0, 1e-12);
  EXPECT_NEAR(out[0].length, 1.0, 1e-12);
  EXPECT_NEAR(out[2].length, 9.0, 1e-12);
  // A large P is held to the same half.
  out = corner({2, 0, 0, 0, 0, 0, 0, 0, 0}, {2, 10, 0, 0, 0, 0, 0, 0, 0}, 5);
  EXPECT_NEAR(out[1].radius, 1.0, 1e-12);
  // The arc's speed limit comes from its curvature: within 0.98 of the acceleration limit.
  EXPECT_LE(out[1].axis_velocity * out[1].axis_velocity / out[1].radius, 0.98 * 2000 + 1e-9);
}

TEST(BlendGeometry, StraightOnIsTangentAndReversalsStop) {
  auto out = corner({5, 0, 0, 0, 0, 0, 0, 0, 0}, {9, 0, 0, 0, 0, 0, 0, 0, 0}, 0.1);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_TRUE(out[0].continuous);
  out = corner({5, 0, 0, 0, 0, 0, 0, 0, 0}, {1, 0, 0, 0, 0, 0, 0, 0, 0}, 0.1);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FALSE(out[0].continuous);
}

// A blend between two lines along X that bend slightly in Z (a sloped surface): the arc's
// tangent lies along X and its normal along Z, so the tangential acceleration is X's (2000),
// not the plane's weakest axis (Z, 1000), while every axis stays within its limit with the
// centripetal part included; a blend in XY, where both axes carry both parts, keeps the
// orthogonal split.
TEST(BlendGeometry, ASlopeBlendKeepsTheTangentAxisAcceleration) {
  const auto config = small_mill();
  const auto slope = corner(AxisPose{10, 0, 0.2}, AxisPose{20, 0, 0}, 0.01);
  ASSERT_EQ(slope.size(), 3u);
  const Segment& arc = slope[1];
  ASSERT_EQ(arc.kind, Segment::Kind::blend);
  EXPECT_GT(arc.max_acceleration, 1900);
  // The worst case over the sweep: tangential along X at most 2000, and Z's share of the
  // tangential plus the centripetal part at the arc's speed limit within Z's 1000.
  const double speed = std::min(arc.axis_velocity, 100.0 * config.max_feed_override);
  const double a_n = speed * speed / arc.radius;
  for (double f = 0; f <= 1.0; f += 0.125) {
    const double phi = arc.sweep * f;
    for (int i = 0; i < 3; ++i) {
      const double t = -std::sin(phi) * arc.blend_u[i] + std::cos(phi) * arc.blend_v[i];
      const double n = -(std::cos(phi) * arc.blend_u[i] + std::sin(phi) * arc.blend_v[i]);
      EXPECT_LE(std::abs(arc.max_acceleration * t) + std::abs(a_n * n),
                config.axes[static_cast<std::size_t>(i)].max_acceleration * (1 + 1e-9))
          << "axis " << i << " at " << f;
    }
  }
  const auto flat = corner(AxisPose{10, 0, 0}, AxisPose{20, 10, 0}, 0.5);
  ASSERT_EQ(flat.size(), 3u);
  EXPECT_LE(flat[1].max_acceleration, 2000);
}

}  // namespace
}  // namespace cncd::test
