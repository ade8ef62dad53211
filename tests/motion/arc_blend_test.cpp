// G64 fillets where a programmed arc meets a line or another arc: tangent to both curves,
// within P of the corner, at most half of each move, crossed at speed; corners where no useful
// fillet fits, and G61/G61.1, stop as before.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"
#include "path_distance.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Move;
using motion::Segment;

// Plans the moves from the origin in `mode` with tolerance `p` and returns the segments.
std::deque<Segment> plan(std::vector<Move> moves, Move::PathMode mode, double p) {
  static const auto config = small_mill();
  motion::Planner planner(config);
  planner.reset(AxisPose{});
  std::string error;
  for (auto& move : moves) {
    move.path_mode = mode;
    move.tolerance = p;
    EXPECT_TRUE(planner.push(move, true, error)) << error;
  }
  planner.flush();
  return planner.output();
}

struct Measured {
  int periods = 0;
  double corner_speed = 0;  // path speed at the period closest to the corner, units/s
  double closest = 1e9;     // closest approach to the corner
  double deviation = 0;     // largest distance from the programmed moves
};

// Runs the moves from the origin and measures them around `corner`.
Measured run(std::vector<Move> moves, Move::PathMode mode, double p, const AxisPose& corner) {
  VirtualMachine m(small_mill());
  m.ready();
  const AxisPose start = m.status().commanded;
  for (auto& move : moves) {
    move.path_mode = mode;
    move.tolerance = p;
    m.queue(move);
  }
  Measured r;
  r.periods = m.run_until_idle();
  expect_within_limits(m, start);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], moves.back().end[0]);
  EXPECT_DOUBLE_EQ(m.status().commanded[1], moves.back().end[1]);
  EXPECT_EQ(m.status().moves_done, moves.size());
  const auto& points = m.trajectory();
  std::size_t nearest = 1;
  for (std::size_t k = 1; k < points.size(); ++k) {
    const double d = xyz_distance(points[k], corner);
    if (d < r.closest) {
      r.closest = d;
      nearest = k;
    }
    double off = 1e9;
    AxisPose from = start;
    for (const auto& move : moves) {
      off = std::min(off, distance_to_move(points[k], from, move));
      from = move.end;
    }
    r.deviation = std::max(r.deviation, off);
  }
  r.corner_speed = xyz_distance(points[nearest], points[nearest - 1]) / m.period_s();
  return r;
}

// 20 mm along X at F6000, then a quarter circle of R10 turning left from heading +Y: a
// 90 degree corner between a line and an arc.
std::vector<Move> line_into_quarter_arc() {
  return {line_to(Move::Kind::feed, 20, 0, 0, 100), arc_to(10, 10, 10, 0, 1, 100)};
}

TEST(ArcBlend, LineIntoQuarterArcIsFilletedTangentAndWithinP) {
  const auto out = plan(line_into_quarter_arc(), Move::PathMode::blend, 0.2);
  ASSERT_EQ(out.size(), 3u);
  const Segment& line = out[0];
  const Segment& fillet = out[1];
  const Segment& arc = out[2];
  ASSERT_EQ(fillet.kind, Segment::Kind::blend);
  EXPECT_TRUE(fillet.fillet);
  EXPECT_TRUE(line.continuous && fillet.continuous && !arc.continuous);
  EXPECT_EQ(line.moves + fillet.moves + arc.moves, 2u);
  EXPECT_EQ(line.end, fillet.start);
  EXPECT_EQ(fillet.end, arc.start);
  // Tangent at both ends, on its circle in between.
  const double h = 1e-6 * fillet.length;
  const AxisPose p0 = fillet.point_at(0), p1 = fillet.point_at(h);
  const AxisPose q0 = fillet.point_at(fillet.length - h), q1 = fillet.point_at(fillet.length);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR((p1[i] - p0[i]) / h, line.end_direction[i], 1e-6);
    EXPECT_NEAR((q1[i] - q0[i]) / h, arc.start_direction[i], 1e-6);
  }
  // The trimmed arc still lies on the programmed circle, from its new start to the end, and
  // its length, directions and points agree.
  EXPECT_NEAR(arc.length, arc.radius * std::abs(arc.sweep), 1e-12);
  EXPECT_NEAR(std::hypot(arc.start[0] - 10, arc.start[1]), 10, 1e-9);
  const AxisPose a0 = arc.point_at(0), a1 = arc.point_at(h);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(a0[i], arc.start[i], 1e-9);
    EXPECT_NEAR((a1[i] - a0[i]) / h, arc.start_direction[i], 1e-6);
  }
  EXPECT_NEAR(arc.point_at(arc.length)[0], 10, 1e-12);
  EXPECT_NEAR(arc.point_at(arc.length)[1], 10, 1e-12);
  // P binds: the fillet passes P from the corner and no point of it is further than P from
  // the programmed path.
  const AxisPose corner{20, 0, 0, 0, 0, 0, 0, 0, 0};
  double closest = 1e9, furthest = 0;
  const auto moves = line_into_quarter_arc();
  for (int k = 0; k <= 1000; ++k) {
    const AxisPose p = fillet.point_at(fillet.length * k / 1000);
    closest = std::min(closest, xyz_distance(p, corner));
    furthest = std::max(furthest, std::min(distance_to_move(p, AxisPose{}, moves[0]),
                                           distance_to_move(p, corner, moves[1])));
  }
  EXPECT_NEAR(closest, 0.2, 1e-6);
  EXPECT_LE(furthest, 0.2 + 1e-9);
  // Under half of each move.
  EXPECT_LE(20 - line.length, 10 + 1e-9);
  EXPECT_LE(10 * std::numbers::pi / 2 - arc.length, 2.5 * std::numbers::pi + 1e-9);
}

TEST(ArcBlend, LineIntoQuarterArcIsCrossedAtSpeedWithinPWhereG61Stops) {
  const AxisPose corner{20, 0, 0, 0, 0, 0, 0, 0, 0};
  const Measured blended = run(line_into_quarter_arc(), Move::PathMode::blend, 0.2, corner);
  const Measured exact = run(line_into_quarter_arc(), Move::PathMode::exact_path, 0.2, corner);
  EXPECT_GT(blended.corner_speed, 20.0);
  EXPECT_LT(exact.corner_speed, 2.0);
  EXPECT_LE(blended.deviation, 0.2 + 1e-6);
  EXPECT_GE(blended.closest, 0.2 - 1e-9);
  EXPECT_LE(exact.deviation, 1e-6);
  EXPECT_LT(blended.periods, exact.periods);
}

// An S: a counter-clockwise arc, then a clockwise one that starts 40 degrees off its tangent,
// then a line leaving that arc at a corner.
TEST(ArcBlend, ArcIntoReversedArcAndArcIntoLineAreFilletedAndCrossedAtSpeed) {
  const double turn = 40 * std::numbers::pi / 180;
  // First arc: R10 about (0, 10) from the origin through a quarter turn, to (10, 10) heading
  // +Y. Second: R8, clockwise, starting at heading +Y turned 40 degrees right.
  const double h = std::numbers::pi / 2 - turn;  // heading of the second arc's start
  const double cx = 10 + 8 * std::sin(h), cy = 10 - 8 * std::cos(h);
  const double a1 = h + std::numbers::pi / 2 - 1.2;  // clockwise by 1.2 rad
  const double ex = cx + 8 * std::cos(a1), ey = cy + 8 * std::sin(a1);
  std::vector<Move> moves{arc_to(10, 10, 0, 10, 1, 100), arc_to(ex, ey, cx, cy, -1, 100),
                          line_to(Move::Kind::feed, ex + 10, ey, 0, 100)};
  const auto out = plan(moves, Move::PathMode::blend, 0.1);
  int fillets = 0;
  for (const auto& seg : out) {
    fillets += seg.fillet ? 1 : 0;
    if (&seg != &out.back()) {
      EXPECT_TRUE(seg.continuous);
    }
  }
  EXPECT_EQ(fillets, 2);
  const Measured blended = run(moves, Move::PathMode::blend, 0.1, {10, 10, 0, 0, 0, 0, 0, 0, 0});
  const Measured exact = run(moves, Move::PathMode::exact_path, 0.1, {10, 10, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_GT(blended.corner_speed, 10.0);
  EXPECT_LT(exact.corner_speed, 2.0);
  EXPECT_LE(blended.deviation, 0.1 + 1e-6);
  EXPECT_LT(blended.periods, exact.periods);
}

// A 90 degree corner onto an arc of R10 and 5e-5 rad (0.5 um): a fillet within half of it
// would have to be crossed at under 1% of the feed, so the corner stops as before, even with
// a P that would allow a fillet of millimetres.
TEST(ArcBlend, CornerWhoseFilletNeedsMoreThanHalfAMoveStops) {
  const double a = 5e-5;
  std::vector<Move> moves{line_to(Move::Kind::feed, 20, 0, 0, 100),
                          arc_to(10 + 10 * std::cos(a), 10 * std::sin(a), 10, 0, 1, 100),
                          line_to(Move::Kind::feed, 20, 20, 0, 100)};
  // The arc here starts heading +Y: the line into it turns by 90 degrees.
  const auto out = plan(moves, Move::PathMode::blend, 1.0);
  ASSERT_GE(out.size(), 2u);
  EXPECT_NE(out[1].kind, Segment::Kind::blend);
  EXPECT_FALSE(out[0].continuous);
  const Measured r = run(moves, Move::PathMode::blend, 1.0, {20, 0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_LT(r.corner_speed, 2.0);
  EXPECT_LE(r.deviation, 1.0 + 1e-6);
}

// A line into an arc 1 mrad off its tangent that curves back the other way: fillets of any
// radius fit, tending to a straight line; the radius stays bounded so that the fillet's
// points, computed from its centre, are exact.
TEST(ArcBlend, NearlyTangentArcCurvingBackGetsAnExactFillet) {
  const double kink = 1e-3;
  const double cx = 20 + 10 * std::sin(kink), cy = -10 * std::cos(kink);
  const double end = std::numbers::pi / 2 + kink - 1;
  std::vector<Move> moves{
      line_to(Move::Kind::feed, 20, 0, 0, 100),
      arc_to(cx + 10 * std::cos(end), cy + 10 * std::sin(end), cx, cy, -1, 100)};
  const auto out = plan(moves, Move::PathMode::blend, 0.01);
  ASSERT_EQ(out.size(), 3u);
  const Segment& fillet = out[1];
  ASSERT_TRUE(fillet.fillet);
  EXPECT_LE(fillet.radius, 1e3 * (10 + 5) * (1 + 1e-12));
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(fillet.point_at(0)[i], fillet.start[i], 1e-9);
    EXPECT_NEAR(fillet.point_at(fillet.length * (1 - 1e-12))[i], fillet.end[i], 1e-9);
  }
  const Measured r = run(moves, Move::PathMode::blend, 0.01, {20, 0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_GT(r.corner_speed, 90.0);
  EXPECT_LE(r.deviation, 0.01 + 1e-6);
}

TEST(ArcBlend, ExactPathAndExactStopNeverFillet) {
  for (const auto mode : {Move::PathMode::exact_path, Move::PathMode::exact_stop}) {
    const auto out = plan(line_into_quarter_arc(), mode, 0.2);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_FALSE(out[0].continuous);
    for (const auto& seg : out)
      EXPECT_NE(seg.kind, Segment::Kind::blend);
  }
}

// A helix, or a line that leaves the arc's plane, keeps today's behaviour: no fillet.
TEST(ArcBlend, HelicesAndLinesLeavingThePlaneAreNotFilleted) {
  Move helix = arc_to(10, 10, 10, 0, 1, 100);
  helix.end[2] = 2;
  auto out = plan({line_to(Move::Kind::feed, 20, 0, 0, 100), helix}, Move::PathMode::blend, 0.2);
  for (const auto& seg : out)
    EXPECT_NE(seg.kind, Segment::Kind::blend);
  out = plan({line_to(Move::Kind::feed, 20, 0, 1, 100), arc_to(10, 10, 10, 0, 1, 100)},
             Move::PathMode::blend, 0.2);
  for (const auto& seg : out)
    EXPECT_NE(seg.kind, Segment::Kind::blend);
}

}  // namespace
}  // namespace cncd::test
