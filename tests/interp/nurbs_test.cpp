// The exact spline curve (NurbsCurve) and its cut into straight pieces, and the curves the
// interpreter builds for G5, G5.1 and G5.2: deviation measured against dense samples of the
// exact curve, exact end points, tangent continuity of a G5 chain.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "canon_recorder.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/nurbs.hpp"

namespace cncd::interp {
namespace {

Pose xy(double x, double y) {
  Pose p{};
  p[0] = x;
  p[1] = y;
  p[2] = -1.5;  // the other axes ride along unchanged
  return p;
}

NurbsFeed curve_of(std::vector<Pose> points, std::vector<double> weights, int order) {
  NurbsFeed feed;
  feed.points = std::move(points);
  feed.weights = std::move(weights);
  feed.order = order;
  return feed;
}

// The largest distance from dense samples of the exact curve to the polyline (from the
// curve's start). Samples and pieces both run along the curve, so each sample looks for its
// nearest piece among those near the last one found.
double deviation(const NurbsCurve& curve, const std::vector<Pose>& pieces) {
  std::vector<Pose> line{curve.start()};
  line.insert(line.end(), pieces.begin(), pieces.end());
  double worst = 0;
  std::size_t at = 1;
  constexpr int kSamples = 8000;
  for (int i = 0; i <= kSamples; ++i) {
    const Pose p = curve.at(static_cast<double>(i) / kSamples);
    double best = 1e300;
    const std::size_t from = at > 200 ? at - 200 : 1;
    const std::size_t to = std::min(line.size(), at + 200);
    for (std::size_t s = from; s < to; ++s) {
      const double d = xy_distance_to_segment(p, line[s - 1], line[s]);
      if (d < best) {
        best = d;
        at = s;
      }
    }
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(NurbsCurve, RandomSplinesStayWithinTheToleranceAndEndExactly) {
  std::mt19937 random(20261129);
  std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
  std::uniform_real_distribution<double> weight(0.2, 5.0);
  for (int trial = 0; trial < 24; ++trial) {
    // Bezier cubics and quadratics (G5, G5.1), then NURBS of orders 3 and 4 (G5.2).
    const int kind = trial % 4;
    const int order = kind == 0 ? 4 : kind == 1 ? 3 : kind == 2 ? 3 : 4;
    const int count = kind < 2 ? order : order + 1 + trial % 5;
    std::vector<Pose> points;
    std::vector<double> weights;
    for (int i = 0; i < count; ++i) {
      points.push_back(xy(coordinate(random), coordinate(random)));
      weights.push_back(kind < 2 ? 1.0 : weight(random));
    }
    const NurbsCurve curve(curve_of(points, weights, order));
    const std::vector<Pose> pieces = curve.polyline(0.001);
    ASSERT_FALSE(pieces.empty());
    EXPECT_EQ(pieces.back(), points.back()) << "trial " << trial;  // bit for bit
    EXPECT_LE(deviation(curve, pieces), 0.001) << "trial " << trial;
    for (const Pose& p : pieces)
      EXPECT_EQ(p[2], -1.5);
  }
}

TEST(NurbsCurve, ARationalQuadraticIsAnExactQuarterCircle) {
  const NurbsCurve curve(
      curve_of({xy(10, 0), xy(10, 10), xy(0, 10)}, {1.0, std::sqrt(0.5), 1.0}, 3));
  for (int i = 0; i <= 100; ++i) {
    const Pose p = curve.at(i / 100.0);
    EXPECT_NEAR(std::hypot(p[0], p[1]), 10.0, 1e-12);
  }
  EXPECT_NEAR(curve.length(), 5.0 * M_PI, 1e-5);
}

TEST(NurbsCurve, KnotsAreClampedAndUniform) {
  // Order 3 on four points: knots 0 0 0 1/2 1 1 1. At the interior knot a quadratic B-spline
  // passes through the middle of the two inner points; the ends are the end points.
  const NurbsCurve curve(curve_of({xy(0, 0), xy(0, 10), xy(10, 10), xy(10, 0)}, {1, 1, 1, 1}, 3));
  EXPECT_NEAR(curve.at(0.5)[0], 5.0, 1e-12);
  EXPECT_NEAR(curve.at(0.5)[1], 10.0, 1e-12);
  EXPECT_EQ(curve.at(0.0), xy(0, 0));
  EXPECT_NEAR(curve.at(1.0)[0], 10.0, 1e-12);
  // With as many points as its order the curve is the Bezier curve.
  const NurbsCurve cubic(curve_of({xy(0, 0), xy(1, 2), xy(9, -2), xy(10, 0)}, {1, 1, 1, 1}, 4));
  for (const double u : {0.1, 0.37, 0.5, 0.81}) {
    const double a = 1 - u;
    const double x = 3 * a * a * u * 1 + 3 * a * u * u * 9 + u * u * u * 10;
    const double y = 3 * a * a * u * 2 + 3 * a * u * u * -2;
    EXPECT_NEAR(cubic.at(u)[0], x, 1e-12);
    EXPECT_NEAR(cubic.at(u)[1], y, 1e-12);
  }
}

std::vector<NurbsFeed> splines_of(const std::string& program) {
  Interpreter interp;
  EXPECT_FALSE(interp.open_string(program, "t.ngc"));
  test_support::CanonRecorder sink;
  const auto error = run_program(interp, sink);
  EXPECT_FALSE(error) << (error ? error->to_string() : "");
  return sink.all<NurbsFeed>();
}

TEST(SplineCanon, AG5WithoutIAndJContinuesTheDirectionTheLastG5EndedIn) {
  const auto curves = splines_of(
      "G21 F100\nG1 X0 Y0\nG5 I5 J10 P-5 Q10 X20 Y0\nG5 P-4 Q-3 X40 Y0\nG1 X41\n"
      "G5 X50 Y5 P1 Q1\nM2\n");
  ASSERT_EQ(curves.size(), 3u);
  ASSERT_EQ(curves[0].points.size(), 4u);
  EXPECT_EQ(curves[0].order, 4);
  EXPECT_EQ(curves[0].points[1][0], 5.0);
  EXPECT_EQ(curves[0].points[1][1], 10.0);
  // The second curve leaves its start along the direction the first one arrived in.
  const Pose& a2 = curves[0].points[2];
  const Pose& a3 = curves[0].points[3];
  const Pose& b0 = curves[1].points[0];
  const Pose& b1 = curves[1].points[1];
  EXPECT_EQ(a3, b0);
  const double cross = (a3[0] - a2[0]) * (b1[1] - b0[1]) - (a3[1] - a2[1]) * (b1[0] - b0[0]);
  const double dot = (a3[0] - a2[0]) * (b1[0] - b0[0]) + (a3[1] - a2[1]) * (b1[1] - b0[1]);
  EXPECT_NEAR(cross, 0.0, 1e-12);
  EXPECT_GT(dot, 0.0);
  // So do the first and last straight pieces either side of the joint, within the tolerance.
  const auto first = NurbsCurve(curves[0]).polyline(0.001);
  const auto second = NurbsCurve(curves[1]).polyline(0.001);
  const Pose& before = first[first.size() - 2];
  const double in = std::atan2(a3[1] - before[1], a3[0] - before[0]);
  const double out = std::atan2(second[0][1] - b0[1], second[0][0] - b0[0]);
  EXPECT_LT(std::fabs(in - out), 0.05);
  // rs274 keeps the last P and Q across other moves: the third curve starts along (4, 3).
  EXPECT_EQ(curves[2].points[1][0], 41.0 + 4.0);
  EXPECT_EQ(curves[2].points[1][1], 0.0 + 3.0);
}

TEST(SplineCanon, G52PointsCountFromTheStartAndTheCurveEndsOnTheLast) {
  const auto curves = splines_of(
      "G21 F100\nG1 X1 Y0\nG91 G5.2 P2\nX1 Y1 P1 L4\nX2 Y3 P3\nX3 Y0 P2\nG5.3\nG90 G1 X9\nM2\n");
  ASSERT_EQ(curves.size(), 1u);
  const NurbsFeed& c = curves[0];
  EXPECT_EQ(c.order, 4);
  ASSERT_EQ(c.points.size(), 4u);
  EXPECT_EQ(c.points[0][0], 1.0);
  EXPECT_EQ(c.points[3][0], 4.0);  // 1 + 3: incremental from where the curve starts
  EXPECT_EQ(c.weights, (std::vector<double>{2, 1, 3, 2}));
}

}  // namespace
}  // namespace cncd::interp
