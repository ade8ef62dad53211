// Planner properties in virtual time: no axis ever exceeds its velocity or acceleration limit,
// moves end exactly where programmed, arcs stay on their circle.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Move;

// Largest ratio of measured per-axis velocity and acceleration over the axis's limit.
struct Peaks {
  double velocity_ratio = 0;
  double acceleration_ratio = 0;
};

Peaks measure(const VirtualMachine& m, const motion::AxisPose& start) {
  Peaks peaks;
  const double dt = m.period_s();
  std::vector<motion::AxisPose> points{start};
  points.insert(points.end(), m.trajectory().begin(), m.trajectory().end());
  for (int axis = 0; axis < 3; ++axis) {
    const auto& limits = m.config().axes[static_cast<std::size_t>(axis)];
    double previous_v = 0;
    for (std::size_t k = 1; k < points.size(); ++k) {
      const double v = (points[k][axis] - points[k - 1][axis]) / dt;
      const double a = (v - previous_v) / dt;
      peaks.velocity_ratio = std::max(peaks.velocity_ratio, std::abs(v) / limits.max_velocity);
      peaks.acceleration_ratio =
          std::max(peaks.acceleration_ratio, std::abs(a) / limits.max_acceleration);
      previous_v = v;
    }
  }
  return peaks;
}

TEST(Planner, RandomLinesStayWithinEveryAxisLimitAndEndExactly) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> pos(-300, 300);
  std::uniform_real_distribution<double> feed(1, 400);
  std::bernoulli_distribution rapid(0.3);
  VirtualMachine m(small_mill());
  m.ready();
  const auto start = m.status().commanded;
  motion::AxisPose end{};
  for (int i = 0; i < 40; ++i) {
    const double x = pos(rng), y = pos(rng), z = pos(rng) / 2;
    m.queue(line_to(rapid(rng) ? Move::Kind::traverse : Move::Kind::feed, x, y, z, feed(rng)));
    end = {x, y, z};
  }
  m.run_until_idle();
  const Peaks peaks = measure(m, start);
  EXPECT_LE(peaks.velocity_ratio, 1.001);
  EXPECT_LE(peaks.acceleration_ratio, 1.001);
  EXPECT_GT(peaks.velocity_ratio, 0.5);  // the test does exercise the limits
  const auto final_pose = m.status().commanded;
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_EQ(final_pose[axis], end[axis]);
}

TEST(Planner, ShortMovesRespectLimitsToo) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> step(-0.2, 0.2);
  VirtualMachine m(small_mill());
  m.ready();
  const auto start = m.status().commanded;
  double x = 0, y = 0;
  for (int i = 0; i < 500; ++i) {
    x += step(rng);
    y += step(rng);
    m.queue(line_to(Move::Kind::feed, x, y, 0, 6000.0 / 60));
  }
  m.run_until_idle();
  const Peaks peaks = measure(m, start);
  EXPECT_LE(peaks.velocity_ratio, 1.001);
  EXPECT_LE(peaks.acceleration_ratio, 1.001);
  EXPECT_EQ(m.status().commanded[0], x);
  EXPECT_EQ(m.status().commanded[1], y);
}

TEST(Planner, ArcsStayOnTheirCircleWithinLimits) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(0.5, 80);
  std::uniform_int_distribution<int> turns(-2, 2);
  VirtualMachine m(small_mill());
  m.ready();
  for (int i = 0; i < 12; ++i) {
    const double r = radius(rng);
    int t = turns(rng);
    if (t == 0) t = 1;
    const auto from = m.status().commanded;
    m.clear_trajectory();
    Move arc;
    arc.kind = Move::Kind::arc;
    arc.center_first = from[0] - r;  // start on the circle's +X side
    arc.center_second = from[1];
    arc.end = {arc.center_first, from[1] + r, from[2] + 1.0, 0, 0, 0, 0, 0, 0};  // helix
    arc.turns = t;
    arc.feed = 9000.0 / 60;
    m.queue(arc);
    m.run_until_idle();
    const Peaks peaks = measure(m, from);
    EXPECT_LE(peaks.velocity_ratio, 1.001) << "r=" << r << " turns=" << t;
    EXPECT_LE(peaks.acceleration_ratio, 1.001) << "r=" << r << " turns=" << t;
    for (const auto& p : m.trajectory()) {
      ASSERT_NEAR(std::hypot(p[0] - arc.center_first, p[1] - arc.center_second), r, 1e-9);
    }
    EXPECT_EQ(m.status().commanded[0], arc.end[0]);
    EXPECT_EQ(m.status().commanded[1], arc.end[1]);
    EXPECT_EQ(m.status().commanded[2], arc.end[2]);
    // Turns: |sweep| = quarter turn + (|t| - 1) full turns, either direction.
    motion::Planner planner(m.config());
    std::string error;
    const auto seg = planner.plan(arc, from, true, error);
    ASSERT_TRUE(seg.has_value());
    const double quarter = std::numbers::pi / 2;
    const double expected = t > 0 ? quarter + 2 * std::numbers::pi * (t - 1)
                                  : -(3 * quarter) - 2 * std::numbers::pi * (-t - 1);
    EXPECT_NEAR(seg->sweep, expected, 1e-9);
  }
}

// A slow arc and a slow corner's blend arc: their acceleration is split between speeding up and
// turning for the fastest speed the feed can ask for (at MAX_FEED_OVERRIDE), so their speed
// limit of the axes alone is that speed too. A path that does not slow to the feed in time
// (S-curve profiles after the override drops) is then still held within the axis limits.
TEST(Planner, SlowCurvesAreLimitedToTheSpeedTheirAccelerationSplitAllows) {
  auto config = small_mill();
  config.max_feed_override = 1.5;
  motion::Planner planner(config);
  planner.reset(motion::AxisPose{});
  std::string error;
  Move arc;
  arc.kind = Move::Kind::arc;
  arc.center_first = -2;
  arc.center_second = 0;
  arc.end = {-2, 2, 0, 0, 0, 0, 0, 0, 0};
  arc.turns = 1;
  arc.feed = 10;
  const auto seg = planner.plan(arc, motion::AxisPose{}, true, error);
  ASSERT_TRUE(seg.has_value()) << error;
  EXPECT_NEAR(seg->axis_velocity, 15, 1e-9);
  const double turning = seg->axis_velocity * seg->axis_velocity / 2;
  EXPECT_LE(std::hypot(turning, seg->max_acceleration), 2000 * (1 + 1e-9));
  Move first = line_to(Move::Kind::feed, 10, 0, 0, 10);
  first.path_mode = Move::PathMode::blend;
  Move second = line_to(Move::Kind::feed, 10, 10, 0, 10);
  second.path_mode = Move::PathMode::blend;
  ASSERT_TRUE(planner.push(first, true, error)) << error;
  ASSERT_TRUE(planner.push(second, true, error)) << error;
  planner.flush();
  int blends = 0;
  for (const auto& out : planner.output()) {
    if (out.kind != motion::Segment::Kind::blend) continue;
    ++blends;
    EXPECT_LE(out.axis_velocity, 15 * (1 + 1e-9));
  }
  EXPECT_EQ(blends, 1);
}

TEST(Planner, ExactStopTimeMatchesTheTrapezoid) {
  VirtualMachine m(small_mill());
  m.ready();
  // 100 mm in X at F6000 (100 mm/s): 0.05 s up, 0.95 s cruise, 0.05 s down = 1.05 s.
  m.queue(line_to(Move::Kind::feed, 100, 0, 0, 100));
  const int cycles = m.run_until_idle();
  EXPECT_NEAR(cycles * m.period_s(), 1.05, 0.003);
  // A rapid of 100 mm along X and Y: each axis would allow 200, the diagonal is capped by
  // [TRAJ] MAX_LINEAR_VELOCITY = 250 -> 250 mm/s, acceleration by 2000/cos45.
  m.queue(line_to(Move::Kind::traverse, 200, 100, 0));
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[0], 200);
}

// Rest-to-rest time of a trapezoid (or triangle) over `length` with limits v and a.
double trapezoid_time(double length, double v, double a) {
  if (length >= v * v / a) return length / v + v / a;
  return 2 * std::sqrt(length / a);
}

TEST(Planner, ExactStopTimeIsTheAnalyticTrapezoidForRandomMoves) {
  std::mt19937 rng(4321);
  std::uniform_real_distribution<double> coordinate(-200, 200);
  std::uniform_real_distribution<double> feed(0.5, 400);
  std::bernoulli_distribution tiny(0.2);
  VirtualMachine m(small_mill());
  m.ready();
  const auto& axes = m.config().axes;
  for (int i = 0; i < 60; ++i) {
    const auto from = m.status().commanded;
    motion::AxisPose to = from;
    const bool short_move = tiny(rng);  // triangles as well as trapezoids
    for (int axis = 0; axis < 3; ++axis)
      to[axis] = short_move ? from[axis] + coordinate(rng) * 0.005 : coordinate(rng);
    const double f = feed(rng);
    m.queue(line_to(Move::Kind::feed, to[0], to[1], to[2], f));
    // The path limits: the feed, [TRAJ] MAX_LINEAR_VELOCITY, then each axis's limit over its
    // share of the direction.
    const double length = std::hypot(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
    double v = std::min(f, m.config().max_linear_velocity);
    double a = 1e300;
    for (int axis = 0; axis < 3; ++axis) {
      const double share = std::abs(to[axis] - from[axis]) / length;
      if (share == 0) continue;
      v = std::min(v, axes[static_cast<std::size_t>(axis)].max_velocity / share);
      a = std::min(a, axes[static_cast<std::size_t>(axis)].max_acceleration / share);
    }
    const double expected_s = trapezoid_time(length, v, a);
    const int cycles = m.run_until_idle();
    // The move ends inside its last period, and the loop reports idle in that same period.
    EXPECT_NEAR(cycles * m.period_s(), expected_s, m.period_s()) << "move " << i;
    EXPECT_EQ(m.status().commanded, to);
  }
}

TEST(Planner, RefusesNonFiniteMoves) {
  const auto config = small_mill();
  motion::Planner planner(config);
  std::string error;
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::feed, NAN, 0, 0, 10), {}, false, error));
  EXPECT_NE(error.find("non-finite"), std::string::npos);
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::feed, 1, 0, 0, INFINITY), {}, false, error));
  Move arc;
  arc.kind = Move::Kind::arc;
  arc.feed = 10;
  arc.end = {2, 0, 0};
  arc.center_first = 1;
  arc.plane_axes = {0, 0, 2};
  EXPECT_FALSE(planner.plan(arc, {}, false, error));
  EXPECT_NE(error.find("differ"), std::string::npos) << error;
}

// An absurd target (a work offset of 1e300 that got this far) is refused with a readable
// message naming the axis and its limits, homed or not: never a servo fault.
TEST(Planner, RefusesAbsurdTargetsReadably) {
  const auto config = small_mill();
  motion::Planner planner(config);
  std::string error;
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::traverse, 1e300, 0, 0), {}, true, error));
  EXPECT_EQ(error, "move to X 1e+300 is outside the X soft limits [-1000.0000, 1000.0000]");
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::feed, 0, -2e9, 0, 10), {}, false, error));
  EXPECT_EQ(error, "move to Y -2000000000 is beyond 1e9, the largest coordinate any move may have");
  EXPECT_TRUE(planner.plan(line_to(Move::Kind::feed, 0, -1e9, 0, 10), {}, false, error)) << error;
}

TEST(Planner, RefusesImpossibleMoves) {
  const auto config = small_mill();
  motion::Planner planner(config);
  std::string error;
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::feed, 10, 0, 0, 0), {}, true, error));
  EXPECT_NE(error.find("feed"), std::string::npos);
  EXPECT_FALSE(planner.plan(line_to(Move::Kind::traverse, 0, 0, 600), {}, true, error));
  EXPECT_NE(error.find("Z"), std::string::npos) << error;
  // Soft limits apply only once homed.
  EXPECT_TRUE(planner.plan(line_to(Move::Kind::traverse, 0, 0, 600), {}, false, error));
  Move arc;
  arc.kind = Move::Kind::arc;
  arc.feed = 10;
  arc.end = {10, 0, 0};
  arc.center_first = 1;
  arc.center_second = 0;
  EXPECT_FALSE(planner.plan(arc, {}, true, error));
  EXPECT_NE(error.find("radius"), std::string::npos);
  // An arc whose bulge leaves the limits is refused even though both ends are inside:
  // counterclockwise from (0,0) around (500,0) to (1000,0) passes through (500,-500).
  Move bulge;
  bulge.kind = Move::Kind::arc;
  bulge.feed = 10;
  bulge.end = {1000, 0, 0};
  bulge.center_first = 500;
  bulge.center_second = 0;
  bulge.turns = 1;
  config::MachineConfig tight = config;
  tight.axes[1].min_limit = -100;
  EXPECT_FALSE(motion::Planner(tight).plan(bulge, {}, true, error).has_value());
  EXPECT_NE(error.find("Y"), std::string::npos) << error;
  bulge.turns = -1;  // clockwise passes through (500,500) instead: inside
  EXPECT_TRUE(motion::Planner(tight).plan(bulge, {}, true, error).has_value()) << error;
}

}  // namespace
}  // namespace cncd::test
