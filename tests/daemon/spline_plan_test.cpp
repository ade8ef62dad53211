// Splines through the plan simulation (the feeder, the look-ahead planner and the servo loop
// cncd-check --plan runs): the commanded path stays within 0.001 mm of the exact curve, the
// pieces blend without stopping, the tool ends on the end point.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/interp/nurbs.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

interp::Pose xy(double x, double y) {
  interp::Pose p{};
  p[0] = x;
  p[1] = y;
  return p;
}

// A fine cut of the exact curve, to measure against.
std::vector<interp::Pose> exact(const std::vector<interp::Pose>& points,
                                const std::vector<double>& weights, int order) {
  interp::NurbsFeed feed;
  feed.points = points;
  feed.weights = weights;
  feed.order = order;
  const interp::NurbsCurve curve(feed);
  std::vector<interp::Pose> line{curve.start()};
  for (const auto& p : curve.polyline(1e-6))
    line.push_back(p);
  return line;
}

double distance_to(const std::vector<interp::Pose>& line, double x, double y) {
  double best = 1e300;
  for (std::size_t s = 1; s < line.size(); ++s)
    best = std::min(best, interp::xy_distance_to_segment(xy(x, y), line[s - 1], line[s]));
  return best;
}

TEST(SplinePlan, TheToolFollowsTheCurvesWithinAMicrometreAndEndsOnTheirEnds) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path());
  const auto loaded = config::load_machine_config(ini);
  ASSERT_TRUE(loaded.ok());
  pipeline::PlanSimOptions options;
  options.interp = pipeline::interpreter_options(*loaded.config);
  // Line 3: a G5 cubic; line 4: G5.1; lines 5-9: an order 4 NURBS with weights; G64 without P.
  const std::string program =
      "G21 G90 G64 F1200\nG0 X0 Y0\nG5 I5 J10 P-5 Q10 X20 Y0\nG5.1 I5 J-8 X30 Y0\n"
      "G5.2 X30 Y10 P1 L4\nX40 Y20 P3\nX50 Y-10 P0.5\nX60 Y5 P1\nG5.3\nG1 X70\nM2\n";
  const std::vector<std::vector<interp::Pose>> curves{
      exact({xy(0, 0), xy(5, 10), xy(15, 10), xy(20, 0)}, {1, 1, 1, 1}, 4),
      exact({xy(20, 0), xy(25, -8), xy(30, 0)}, {1, 1, 1}, 3),
      exact({xy(30, 0), xy(30, 10), xy(40, 20), xy(50, -10), xy(60, 5)}, {1, 1, 3, 0.5, 1}, 4)};
  double worst = 0;
  double slowest_inside = 1e300;
  double last_x = 0, last_y = 0, last_t = 0;
  bool passed_nurbs_end = false;
  options.on_sample = [&](double t, const motion::AxisPose& p, double) {
    const double x = p[0];
    const double y = p[1];
    // Which curve the tool is on: by X (each runs left to right here), away from the joints.
    const int curve = x < 19.9 ? 0 : x > 20.1 && x < 29.9 ? 1 : x > 30.1 && x < 59.9 ? 2 : -1;
    if (curve >= 0 && !(curve == 2 && y > 0 && x < 30.1)) {
      worst = std::max(worst, distance_to(curves[static_cast<std::size_t>(curve)], x, y));
    }
    // Inside the curves (away from the joints between them, which are corners) the tool never
    // comes to rest between pieces.
    const bool inside = (x > 1 && x < 19) || (x > 21 && x < 29) || (x > 31 && x < 59);
    if (t > last_t && inside && !passed_nurbs_end) {
      slowest_inside = std::min(slowest_inside, std::hypot(x - last_x, y - last_y) / (t - last_t));
    }
    if (x >= 60) passed_nurbs_end = true;
    if (std::fabs(x - 60) < 1e-9 && std::fabs(y - 5) < 1e-9) passed_nurbs_end = true;
    last_x = x;
    last_y = y;
    last_t = t;
  };
  const auto r = pipeline::simulate_plan(*loaded.config, dir.write("spline.ngc", program), options);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  EXPECT_LE(worst, 0.001);
  EXPECT_GT(slowest_inside, 1.0);  // mm/s: no stop at a joint of two pieces
  EXPECT_NEAR(last_x, 70.0, 1e-9);
  EXPECT_NEAR(last_y, 5.0, 1e-9);
  // The moves: one per piece, all from lines 3 to 8 ending in the curve's order.
  EXPECT_GT(r.moves, 20u);
  std::printf("spline plan: %zu moves, worst deviation %.6f mm, %.3f s\n", r.moves, worst,
              r.cycle_time_s);
}

}  // namespace
}  // namespace cncd::test
