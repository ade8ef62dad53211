// The planner benchmark's time-optimal reference: paths whose least time is known in closed
// form, and how it stands against the floors and against cncd's own plan; the references
// within P of path_smooth.hpp.
#include "path_reference.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <random>
#include <sstream>

#include "bench_mill.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "path_floor.hpp"
#include "path_smooth.hpp"
#include "planner_programs.hpp"

namespace cncd::bench {
namespace {

using motion::AxisPose;
using motion::Segment;

Segment line(AxisPose from, AxisPose to, double feed) {
  Segment s;
  s.kind = Segment::Kind::line;
  s.start = from;
  s.end = to;
  s.length = std::hypot(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
  s.feed = feed;
  return s;
}

// An arc in XY about (cx, cy) from `from` through `sweep` (rad, + counter-clockwise).
Segment arc(AxisPose from, double cx, double cy, double sweep, double feed) {
  Segment s;
  s.kind = Segment::Kind::arc;
  s.start = from;
  s.center_first = cx;
  s.center_second = cy;
  s.radius = std::hypot(from[0] - cx, from[1] - cy);
  s.start_angle = std::atan2(from[1] - cy, from[0] - cx);
  s.sweep = sweep;
  s.end = from;
  s.end[0] = cx + s.radius * std::cos(s.start_angle + sweep);
  s.end[1] = cy + s.radius * std::sin(s.start_angle + sweep);
  s.length = s.radius * std::abs(sweep);
  s.feed = feed;
  return s;
}

AxisPose at(double x, double y, double z = 0) {
  AxisPose p{};
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

double exact_s(const config::MachineConfig& m, const std::vector<Segment>& moves) {
  return time_optimal(m, moves, {}).time_s;
}

TEST(PathReference, LineFromRestToRestIsATrapezoidOrATriangle) {
  const auto m = three_axis_mill();  // 200 mm/s, 2000 mm/s^2 per axis
  // 100 mm at 200 mm/s: 0.5 s at speed plus v / a for the two ramps.
  EXPECT_NEAR(exact_s(m, {line(at(0, 0), at(100, 0), 200)}), 0.5 + 0.1, 1e-9);
  // 1 mm never reaches the feed: 2 sqrt(L / a).
  EXPECT_NEAR(exact_s(m, {line(at(0, 0), at(1, 0), 200)}), 2 * std::sqrt(1 / 2000.0), 1e-9);
  // The feed caps the speed below the axes.
  EXPECT_NEAR(exact_s(m, {line(at(0, 0), at(0, 100), 50)}), 2.0 + 50 / 2000.0, 1e-9);
}

TEST(PathReference, LineOfTwoAxesTakesTheTighterAxis) {
  auto m = three_axis_mill();
  m.axes[1].max_acceleration = 1000;
  // X 30 Y 40: X allows 2000 / 0.6, Y 1000 / 0.8 = 1250 mm/s^2 along the path; the speed
  // is the linear limit, 200 mm/s (X would allow 333, Y 250).
  EXPECT_NEAR(exact_s(m, {line(at(0, 0), at(30, 40), 1000)}), 50 / 200.0 + 200 / 1250.0, 1e-9);
}

// A line, a quarter arc of R10 tangent to it and a line tangent to the arc's end.
std::vector<Segment> line_arc_line(double feed) {
  const double q = std::numbers::pi / 2;
  return {line(at(0, 0), at(50, 0), feed), arc(at(50, 0), 50, 10, q, feed),
          line(at(60, 10), at(60, 60), feed)};
}

TEST(PathReference, TangentArcAtTheFeedIsCrossedWithoutSlowing) {
  const auto m = three_axis_mill();
  // Under sqrt(A r) = 141.4 mm/s the arc's curvature needs less than the axes have: the path
  // runs at the feed from the first ramp to the last, through both tangent junctions.
  for (double feed : {50.0, 140.0}) {
    const double length = 100 + 5 * std::numbers::pi;
    const auto r = time_optimal(m, line_arc_line(feed), {});
    EXPECT_NEAR(r.time_s, length / feed + feed / 2000, 1e-3 * r.time_s) << feed;
    EXPECT_EQ(r.stops, 0u);
    EXPECT_NEAR(r.move_s[1], 5 * std::numbers::pi / feed, 1e-3 * r.move_s[1]) << feed;
  }
}

TEST(PathReference, ArcAboveItsCurvatureSpeedIsHeldToWhatTheAxesAllow) {
  const auto m = three_axis_mill();
  // At the arc's ends one axis takes the whole centripetal acceleration, v^2 / r <= A:
  // sqrt(A r) = 141.4 mm/s; midway each takes v^2 / r / sqrt(2): at most 168.2 mm/s.
  const auto r = time_optimal(m, line_arc_line(200), {});
  const double length = 5 * std::numbers::pi;
  EXPECT_GT(r.move_s[1], length / std::sqrt(std::sqrt(2.0) * 2000 * 10));
  EXPECT_LT(r.move_s[1], length / std::sqrt(2000 * 10.0));
  // Halving the grid changes it by far less than 0.5 %.
  ReferenceOptions fine;
  fine.max_step /= 2;
  fine.max_turn /= 2;
  const auto f = time_optimal(m, line_arc_line(200), fine);
  EXPECT_GT(f.steps, r.steps);
  EXPECT_NEAR(f.time_s, r.time_s, 0.001 * r.time_s);
}

TEST(PathReference, RightAngleCornerStopsOnTheExactPath) {
  const auto m = three_axis_mill();
  // 10 mm then 10 mm at right angles: two triangles of 2 sqrt(10 / 2000) each.
  const std::vector<Segment> corner = {line(at(0, 0), at(10, 0), 200),
                                       line(at(10, 0), at(10, 10), 200)};
  const auto exact = time_optimal(m, corner, {});
  EXPECT_EQ(exact.stops, 1u);
  EXPECT_NEAR(exact.time_s, 4 * std::sqrt(10 / 2000.0), 1e-9);
  // Within P 0.1 the corner is a blend of radius r = 0.1 cos(45) / (1 - cos(45)) = 0.2414 mm
  // touching each line r from the corner. At its ends one axis takes all of v^2 / r, midway
  // each takes v^2 / r / sqrt(2): crossed at sqrt(A r) = 21.97 mm/s or faster, never above
  // 26.13 mm/s. Each line's rest is a triangle from rest up to its peak and down to that speed.
  ReferenceOptions blend;
  blend.blend_corners = true;
  blend.tolerance = 0.1;
  const auto within = time_optimal(m, corner, blend);
  EXPECT_EQ(within.blends, 1u);
  EXPECT_EQ(within.stops, 0u);
  const double r = 0.1 * std::cos(std::numbers::pi / 4) / (1 - std::cos(std::numbers::pi / 4));
  const auto crossing_at = [r](double v) {
    const double rest = 10 - r;
    const double peak = std::sqrt(0.5 * v * v + 2000 * rest);
    return 2 * (2 * peak - v) / 2000 + r * std::numbers::pi / 2 / v;
  };
  EXPECT_GT(within.time_s, crossing_at(std::sqrt(std::sqrt(2.0) * 2000 * r)));
  EXPECT_LT(within.time_s, crossing_at(std::sqrt(2000 * r)));
  EXPECT_LT(within.time_s, exact.time_s);
}

TEST(PathReference, LinesWithinQOfOneLineMergeIntoIt) {
  // Two lines bending by 0.01 at their joint, then a corner of 1 mm off the line.
  const std::vector<Segment> moves = {line(at(0, 0), at(5, 0.01), 100),
                                      line(at(5, 0.01), at(10, 0), 100),
                                      line(at(10, 0), at(15, 1), 100)};
  std::vector<std::size_t> last;
  const auto path = merged_path(moves, 0.02, last);
  ASSERT_EQ(path.size(), 2u);
  EXPECT_EQ(last, (std::vector<std::size_t>{1, 2}));
  EXPECT_NEAR(path[0].length, 10, 1e-12);
  EXPECT_EQ(path[0].end, moves[1].end);
  // Within a tighter Q nothing merges; another feed does not merge either.
  EXPECT_EQ(merged_path(moves, 0.005, last).size(), 3u);
  auto slower = moves;
  slower[1].feed = 50;
  EXPECT_EQ(merged_path(slower, 0.02, last).size(), 3u);
  // The merged line is what the reference runs: one trapezoid, no corner.
  ReferenceOptions options;
  options.blend_corners = true;
  options.merge_tolerance = 0.02;
  const auto r = time_optimal(three_axis_mill(), {moves[0], moves[1]}, options);
  EXPECT_NEAR(r.time_s, 10 / 100.0 + 100 / 2000.0, 1e-9);
  EXPECT_EQ(r.move_s[0], 0.0);
}

// A 3D zigzag of short lines over a wave, with arcs between its rows, under `mode`.
std::string zigzag(const std::string& mode) {
  std::ostringstream p;
  p << std::fixed << std::setprecision(4);
  p << "G21 G17 G90 G94\n" << mode << "\nG0 X0 Y0 Z1\nG1 Z0 F6000\n";
  for (int row = 0; row < 4; ++row) {
    const double y = 2.0 * row;
    for (int k = 1; k <= 40; ++k) {
      const double x = row % 2 ? 20 - 0.5 * k : 0.5 * k;
      p << "G1 X" << x << " Y" << y << " Z" << 0.3 * std::sin(x / 3.0 + y) << "\n";
    }
    if (row < 3) p << (row % 2 ? "G2" : "G3") << " Y" << y + 2 << " I0 J1\n";
  }
  p << "G0 Z1\nM2\n";
  return p.str();
}

class PlannedPath : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/cncd-reference-test-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    const auto loaded = config::load_machine_config(write_cncd_ini(dir_));
    ASSERT_TRUE(loaded.ok());
    machine_ = *loaded.config;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // cncd's time over the program's feed moves from `first_line` on, which it collects, and the
  // planner's segments for the whole program.
  double cncd_s(const std::string& text, std::vector<Segment>& moves,
                std::vector<Segment>* segments = nullptr, int first_line = 5) {
    const auto path = dir_ / "p.ngc";
    std::ofstream(path) << text;
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(machine_);
    options.start_machine = interp::Pose{};
    options.on_move = [&](const Segment& move) {
      if (move.line >= first_line && move.feed > 0) moves.push_back(move);
    };
    if (segments != nullptr)
      options.on_segment = [segments](const Segment& s) { segments->push_back(s); };
    const auto r = pipeline::simulate_plan(machine_, path, options);
    EXPECT_TRUE(r.complete()) << (r.error ? r.error->to_string() : "");
    std::size_t first = r.move_line.size(), last = 0;
    for (std::size_t i = 0; i < r.move_line.size(); ++i) {
      if (r.move_line[i] == first_line && first == r.move_line.size()) first = i;
      if (!moves.empty() && r.move_line[i] == moves.back().line) last = i;
    }
    if (first >= r.move_line.size()) return 0;
    const double end = last + 1 < r.move_start_s.size() ? r.move_start_s[last + 1] : r.cycle_time_s;
    return end - r.move_start_s[first];
  }

  std::filesystem::path dir_;
  config::MachineConfig machine_;
};

TEST_F(PlannedPath, ExactReferenceLiesBetweenTheExactPathFloorAndCncdUnderG61) {
  std::vector<Segment> moves;
  const double cncd = cncd_s(zigzag("G61"), moves);
  ASSERT_GT(moves.size(), 150u);
  const auto reference = time_optimal(machine_, moves, {});
  const auto floors = path_floors(machine_, moves);
  EXPECT_GE(reference.time_s, floors.exact_path_s);
  EXPECT_GE(reference.time_s, floors.bound_s);
  // cncd stops at the same corners and runs its arcs within 80 % of their acceleration; its
  // servo period rounds each move's end up to a period.
  EXPECT_LE(reference.time_s, cncd);
  EXPECT_GT(reference.time_s, 0.5 * cncd);
}

TEST_F(PlannedPath, BlendedReferenceIsNoSlowerThanCncdOnItsBlends) {
  // G64 P alone merges within Q = P too: the reference within P and Q runs cncd's geometry.
  std::vector<Segment> moves;
  const double cncd = cncd_s(zigzag("G64 P0.02"), moves);
  ReferenceOptions options;
  options.blend_corners = true;
  options.tolerance = options.merge_tolerance = 0.02;
  const auto reference = time_optimal(machine_, moves, options);
  // The wave's gentle rows merge into a few dozen lines.
  EXPECT_GT(reference.blends, 20u);
  EXPECT_LT(reference.blends, 100u);
  EXPECT_LE(reference.time_s, cncd);
  EXPECT_LT(reference.time_s, time_optimal(machine_, moves, {}).time_s);
}

TEST_F(PlannedPath, PlannerSegmentsTimedWholeLieBetweenTheReferenceAndCncd) {
  // A program of lines alone, from rest to rest: the planner merges within Q = P and blends
  // its corners as the reference within P and Q does, under limits of its own.
  std::ostringstream p;
  p << std::fixed << std::setprecision(4);
  // From rest at the origin, where the simulation starts.
  p << "G21 G17 G90 G94\nG64 P0.02\nG1 X0.5 Y0.15 Z0.4997 F6000\n";
  for (int k = 2; k <= 400; ++k)
    p << "X" << 0.5 * k << " Y" << 3 * std::sin(0.05 * k) << " Z" << 0.5 * std::cos(0.11 * k)
      << "\n";
  p << "M2\n";
  std::vector<Segment> moves, segments;
  const double cncd = cncd_s(p.str(), moves, &segments, 3);
  ASSERT_EQ(moves.size(), 400u);
  ReferenceOptions options;
  options.blend_corners = true;
  options.tolerance = options.merge_tolerance = 0.02;
  const auto reference = time_optimal(machine_, moves, options);
  const auto planned = planned_optimal(machine_, segments, moves.size());
  const auto raised = planned_optimal(machine_, segments, moves.size(), true);
  EXPECT_GT(planned.blends, 50u);
  EXPECT_EQ(planned.blends, reference.blends);
  EXPECT_GE(planned.time_s, reference.time_s);
  EXPECT_LE(raised.time_s, planned.time_s);
  EXPECT_GE(raised.time_s, reference.time_s * (1 - 1e-3));
  // cncd runs those segments period by period: no faster than timed whole, and close to it.
  EXPECT_LE(planned.time_s, cncd);
  EXPECT_LT(cncd, 1.02 * planned.time_s);
}

// The reference smoothed within P (path_smooth.hpp): the moved polyline stays within the shift
// of the programmed one over randomized dense polylines, leaves straight runs, arcs and the
// runs' ends where they are, and is no slower than the corner blends alone.
std::vector<Segment> polyline(const std::vector<AxisPose>& points, double feed = 100) {
  std::vector<Segment> out;
  for (std::size_t i = 1; i < points.size(); ++i)
    out.push_back(line(points[i - 1], points[i], feed));
  return out;
}

// Random dense polylines: a wandering 3D curve sampled at 0.05 to 2 mm with noise, zigzags,
// spikes, collinear stretches and repeated points.
std::vector<AxisPose> random_points(std::mt19937& rng, int kind) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<AxisPose> p{at(0, 0, 0)};
  double heading = 0;
  for (int i = 0; i < 400; ++i) {
    const AxisPose& last = p.back();
    const double step = 0.05 + 1.95 * u(rng);
    if (kind == 0) heading += 0.4 * (u(rng) - 0.5);
    if (kind == 1) heading = (i % 2 ? 0.6 : -0.6);                                     // zigzag
    if (kind == 2 && i % 37 == 0) heading += std::numbers::pi * (0.8 + 0.2 * u(rng));  // spike
    const bool straight = kind == 3 && (i / 20) % 2 == 0;
    const double z = straight ? last[2] : last[2] + 0.2 * (u(rng) - 0.5);
    p.push_back(at(last[0] + step * std::cos(heading), last[1] + step * std::sin(heading), z));
    if (kind == 3 && i % 53 == 0) p.push_back(p.back());  // a repeated point: a zero line
  }
  return p;
}

TEST(PathSmooth, MovedPolylineStaysWithinTheShiftOfTheProgrammedOne) {
  std::mt19937 rng(28);
  for (int kind = 0; kind < 4; ++kind) {
    for (double shift : {0.005, 0.05, 0.3}) {
      const auto moves = polyline(random_points(rng, kind));
      SmoothOptions options;
      options.shift = shift;
      const auto smoothed = smoothed_lines(moves, options);
      ASSERT_EQ(smoothed.size(), moves.size());
      // Sampled every 2 um (the bound holds at every point: a moved point is the programmed one
      // at the same fraction plus at most the shift). The flow uses the room it has.
      const double deviation = polyline_deviation(moves, smoothed, 2e-3, 0);
      EXPECT_LE(deviation, shift + 1e-9) << "kind " << kind << " shift " << shift;
      EXPECT_GT(deviation, 0.5 * shift) << "kind " << kind << " shift " << shift;
      for (std::size_t i = 0; i < moves.size(); ++i) {
        EXPECT_NEAR(smoothed[i].length,
                    std::hypot(smoothed[i].end[0] - smoothed[i].start[0],
                               smoothed[i].end[1] - smoothed[i].start[1],
                               smoothed[i].end[2] - smoothed[i].start[2]),
                    1e-12);
        if (i > 0) {
          EXPECT_EQ(smoothed[i].start, smoothed[i - 1].end);
        }
      }
      EXPECT_EQ(smoothed.front().start, moves.front().start);
      EXPECT_EQ(smoothed.back().end, moves.back().end);
    }
  }
}

TEST(PathSmooth, StraightRunsArcsAndOtherFeedsStay) {
  // A straight run unevenly spaced, then a line of another feed, a rapid and an arc.
  std::vector<Segment> moves = polyline({at(0, 0), at(0.3, 0), at(1.7, 0), at(2, 0), at(4, 0)});
  moves.push_back(line(at(4, 0), at(4, 1), 50));
  Segment rapid = line(at(4, 1), at(5, 1), 0);
  moves.push_back(rapid);
  Segment arc = line(at(5, 1), at(5, 3), 100);
  arc.kind = Segment::Kind::arc;
  moves.push_back(arc);
  SmoothOptions options;
  options.shift = 0.05;
  const auto smoothed = smoothed_lines(moves, options);
  for (std::size_t i = 0; i < moves.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(smoothed[i].start[a], moves[i].start[a], 1e-12) << i;
      EXPECT_NEAR(smoothed[i].end[a], moves[i].end[a], 1e-12) << i;
    }
  }
}

TEST(PathSmooth, NoisyCurveRunsFasterSmoothedThanBlendedWithinTheSameTolerance) {
  // A circle of radius 20 in 0.5 mm chords whose points are off by up to 0.04 mm: the blends
  // follow the noise, the smoothed polyline much less of it.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-0.04, 0.04);
  std::vector<AxisPose> points;
  for (int i = 0; i <= 250; ++i) {
    const double t = i * 0.5 / 20;
    points.push_back(at(20 * std::cos(t) + noise(rng), 20 * std::sin(t) + noise(rng)));
  }
  const auto moves = polyline(points, 200);
  const auto machine = three_axis_mill();
  ReferenceOptions within;
  within.blend_corners = true;
  within.tolerance = 0.1;
  const double blended = time_optimal(machine, moves, within).time_s;
  SmoothOptions options;
  options.shift = 0.05;
  ReferenceOptions rest = within;
  rest.tolerance = 0.05;
  const double smoothed = time_optimal(machine, smoothed_lines(moves, options), rest).time_s;
  EXPECT_LT(smoothed, 0.8 * blended);
}

}  // namespace
}  // namespace cncd::bench
