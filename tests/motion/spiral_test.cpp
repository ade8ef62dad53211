// Arcs whose end radius differs from the start radius (rounded centre words, within LinuxCNC's
// tolerance): run as spirals whose radius goes linearly with the swept angle, ending exactly at
// the programmed end, within every axis limit; a far larger difference is refused.
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Move;

Move arc_to(double x, double y, double z, double cx, double cy, int turns, double feed) {
  Move arc;
  arc.kind = Move::Kind::arc;
  arc.end = {x, y, z, 0, 0, 0, 0, 0, 0};
  arc.center_first = cx;
  arc.center_second = cy;
  arc.turns = turns;
  arc.feed = feed;
  return arc;
}

// Runs `moves` from where the machine stands, recording them afresh, and checks that they stay
// within every axis limit and end exactly at the last one's end.
void run_within_limits(VirtualMachine& m, std::initializer_list<Move> moves) {
  const auto from = m.status().commanded;
  m.clear_trajectory();
  for (const auto& move : moves)
    m.queue(move);
  m.run_until_idle();
  expect_within_limits(m, from);
  EXPECT_EQ(m.status().commanded, std::data(moves)[moves.size() - 1].end);
}

// Runs `arc` from where the machine stands and checks every recorded period against the
// spiral: its radius at the angle swept so far is the start radius plus that fraction of the
// radius change (within `tolerance`), and the move ends exactly at its end.
void run_spiral(VirtualMachine& m, const Move& arc, double tolerance = 1e-9) {
  const auto from = m.status().commanded;
  run_within_limits(m, {arc});

  motion::Planner planner(m.config());
  std::string error;
  const auto seg = planner.plan(arc, from, true, error);
  ASSERT_TRUE(seg.has_value()) << error;
  const double r0 = std::hypot(from[0] - arc.center_first, from[1] - arc.center_second);
  const double r1 = std::hypot(arc.end[0] - arc.center_first, arc.end[1] - arc.center_second);
  EXPECT_NEAR(seg->radius, r0, 1e-12);
  EXPECT_NEAR(seg->radius + seg->radius_change, r1, 1e-12);
  double angle = std::atan2(from[1] - arc.center_second, from[0] - arc.center_first);
  double swept = 0;
  for (const auto& point : m.trajectory()) {
    const double a = std::atan2(point[1] - arc.center_second, point[0] - arc.center_first);
    swept += std::remainder(a - angle, 2 * std::numbers::pi);
    angle = a;
    const double f = swept / seg->sweep;
    ASSERT_GE(f, -1e-12);
    ASSERT_LE(f, 1 + 1e-12);
    const double radius = std::hypot(point[0] - arc.center_first, point[1] - arc.center_second);
    ASSERT_NEAR(radius, r0 + f * (r1 - r0), tolerance) << "at fraction " << f;
    ASSERT_NEAR(point[2], from[2] + f * (arc.end[2] - from[2]), 1e-9);
  }
  EXPECT_NEAR(swept, seg->sweep, 1e-9);
}

// The two programs that real posts produce: I/J rounded so that the end is 2.5 um and 10 um
// off the start's circle.
TEST(Spiral, RoundedCentreWordsRunToTheirEnd) {
  VirtualMachine m(small_mill());
  m.ready();
  m.queue(line_to(Move::Kind::traverse, 10, 10, 0));
  m.run_until_idle();
  // G3 X10.2 Y10.199 I0 J0.2
  run_spiral(m, arc_to(10.2, 10.199, 0, 10, 10.2, 1, 10));
  m.queue(line_to(Move::Kind::traverse, 0, 0, 0));
  m.run_until_idle();
  // G2 X10 Y0 I5.005 J0 F600
  run_spiral(m, arc_to(10, 0, 0, 5.005, 0, -1, 10));
}

void random_spirals(const config::MachineConfig& config, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> radius(0.05, 60);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi);
  std::uniform_int_distribution<int> turns(-2, 2);
  std::uniform_real_distribution<double> feed(5, 250);
  VirtualMachine m(config);
  m.ready();
  for (int i = 0; i < 16; ++i) {
    const auto from = m.status().commanded;
    const double r0 = radius(rng);
    // Up to LinuxCNC's absolute tolerance in mm, or 0.1 % of the radius.
    const double change = unit(rng) * std::max(0.028, 0.001 * r0);
    const double r1 = std::max(0.01, r0 + change);
    const double a0 = angle(rng), a1 = angle(rng);
    const double cx = from[0] - r0 * std::cos(a0), cy = from[1] - r0 * std::sin(a0);
    int t = turns(rng);
    if (t == 0) t = 1;
    const double z = i % 3 == 0 ? from[2] + unit(rng) * 5 : from[2];  // some helices
    SCOPED_TRACE("spiral " + std::to_string(i) + ": r " + std::to_string(r0) + " -> " +
                 std::to_string(r1) + " turns " + std::to_string(t));
    run_spiral(m, arc_to(cx + r1 * std::cos(a1), cy + r1 * std::sin(a1), z, cx, cy, t, feed(rng)));
  }
}

TEST(Spiral, RandomSpiralsStayOnTheSpiralWithinEveryLimit) {
  random_spirals(small_mill(), 11);
}

TEST(Spiral, RandomSpiralsOnSCurveProfilesToo) {
  auto config = small_mill();
  config.max_linear_jerk = 40000;
  random_spirals(config, 12);
}

// At a steady angular rate a spiral's radial and cross terms add to the centripetal part; a
// tiny spiral whose radius shrinks to a fraction of itself (LinuxCNC's absolute tolerance on
// a 0.03 mm arc) still keeps every axis within its limits, at full feed.
TEST(Spiral, TinySpiralWithALargeRelativeChangeStaysWithinTheLimits) {
  VirtualMachine m(small_mill());
  m.ready();
  m.queue(line_to(Move::Kind::traverse, 0.03, 0, 0));
  m.run_until_idle();
  run_spiral(m, arc_to(-0.003, 0, 0, 0, 0, 1, 250));
  run_spiral(m, arc_to(0.03, 0.0001, 0, 0, 0, -3, 250));
}

TEST(Spiral, TangentsAreThoseOfTheSpiral) {
  const auto config = small_mill();
  motion::Planner planner(config);
  std::string error;
  const auto seg = planner.plan(arc_to(-1.02, 0, 0.5, 0, 0, 1, 10), {1, 0, 0}, false, error);
  ASSERT_TRUE(seg.has_value()) << error;
  EXPECT_NEAR(seg->radius_change, 0.02, 1e-15);
  // The unit tangents point where the path goes from each end.
  const double h = 1e-7 * seg->length;
  auto direction = [](const motion::AxisPose& from, const motion::AxisPose& to) {
    motion::AxisPose d{};
    double sum = 0;
    for (int i = 0; i < 3; ++i)
      sum += (to[i] - from[i]) * (to[i] - from[i]);
    for (int i = 0; i < 3; ++i)
      d[i] = (to[i] - from[i]) / std::sqrt(sum);
    return d;
  };
  const auto d0 = direction(seg->point_at(0), seg->point_at(h));
  const auto d1 = direction(seg->point_at(seg->length - h), seg->point_at(seg->length));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(seg->start_direction[i], d0[i], 1e-6) << i;
    EXPECT_NEAR(seg->end_direction[i], d1[i], 1e-6) << i;
  }
  // The radius grows outwards: the start direction leans away from the centre.
  EXPECT_GT(seg->start_direction[0], 0);
  // `length` is the path length at the larger radius: never shorter than the spiral.
  EXPECT_NEAR(seg->length, std::hypot(std::hypot(std::numbers::pi * 1.02, 0.02), 0.5), 1e-12);
}

// The planner takes whatever the interpreter passes in either unit (up to 0.002 sqrt(2) in
// = 0.0718 mm, or 0.1 % of the radius up to 100 times that); a larger difference is not a
// program's arc and is refused, naming the radii.
TEST(Spiral, RadiusDifferenceIsBoundedLikeTheInterpreters) {
  const auto config = small_mill();
  motion::Planner planner(config);
  std::string error;
  const motion::AxisPose start{};
  auto plan = [&](double r0, double r1) {
    return planner.plan(arc_to(r0 + r1, 0, 0, r0, 0, -1, 10), start, false, error).has_value();
  };
  EXPECT_TRUE(plan(5, 5 - 0.0718));
  EXPECT_FALSE(plan(5, 5 - 0.0720));
  EXPECT_NE(error.find("arc radius differs between start and end by 0.072"), std::string::npos)
      << error;
  EXPECT_FALSE(plan(5.1, 4.9));
  EXPECT_TRUE(plan(5000, 5000 - 5));
  EXPECT_TRUE(plan(10000, 10000 - 7));
  EXPECT_FALSE(plan(10000, 10000 - 7.2));  // 0.072 % of the radius, but past the cap
  EXPECT_FALSE(plan(100, 100.2));
  EXPECT_TRUE(plan(200, 200.2));
  // Inch machines: the same figures in inches.
  auto inch = config;
  inch.linear_units = config::LinearUnits::inch;
  motion::Planner inches(inch);
  EXPECT_TRUE(inches.plan(arc_to(2 - 0.0028, 0, 0, 1, 0, -1, 1), start, false, error));
  EXPECT_FALSE(inches.plan(arc_to(2 - 0.0029, 0, 0, 1, 0, -1, 1), start, false, error));
}

// Under G64 a spiral meets its neighbours without a fillet (whose fit is made for circles): a
// line into it and out of it along its (rounded) tangents are crossed as kinks, at speed, and
// the path still ends exactly.
TEST(Spiral, JunctionsGetNoFilletAndThePathEndsExactly) {
  VirtualMachine m(small_mill());
  m.ready();
  m.queue(line_to(Move::Kind::traverse, 10, -10, 0));
  m.run_until_idle();
  const auto from = m.status().commanded;
  Move in = line_to(Move::Kind::feed, 10, 0, 0, 100);
  in.path_mode = Move::PathMode::blend;
  Move arc = arc_to(20, 0, 0, 15.005, 0, -1, 100);
  arc.path_mode = Move::PathMode::blend;
  Move out = line_to(Move::Kind::feed, 20, -10, 0, 100);
  out.path_mode = Move::PathMode::blend;
  motion::Planner planner(m.config());
  planner.reset(from);
  std::string error;
  ASSERT_TRUE(planner.push(in, true, error)) << error;
  ASSERT_TRUE(planner.push(arc, true, error)) << error;
  ASSERT_TRUE(planner.push(out, true, error)) << error;
  planner.flush();
  const auto& segments = planner.output();
  ASSERT_EQ(segments.size(), 3u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_NE(segments[k].kind, motion::Segment::Kind::blend);
    EXPECT_TRUE(segments[k].continuous) << k;
    EXPECT_GT(segments[k].junction_velocity, 50) << k;
  }
  EXPECT_NE(segments[1].radius_change, 0);
  run_within_limits(m, {in, arc, out});
}

}  // namespace
}  // namespace cncd::test
