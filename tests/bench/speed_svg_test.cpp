// The planner benchmark's speed picture: its axis ticks, the window it picks, and the
// reference's speed profile it draws.
#include "speed_svg.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bench_mill.hpp"
#include "path_reference.hpp"

namespace cncd::bench {
namespace {

TEST(SpeedSvg, TicksAreRoundStepsWithinTheRange) {
  EXPECT_EQ(nice_ticks(0, 163, 7), (std::vector<double>{0, 50, 100, 150}));
  EXPECT_EQ(nice_ticks(3054, 3094, 11),
            (std::vector<double>{3055, 3060, 3065, 3070, 3075, 3080, 3085, 3090}));
  EXPECT_EQ(nice_ticks(0, 1, 11).size(), 11u);  // steps of 0.1
  EXPECT_TRUE(nice_ticks(5, 5, 7).empty());
}

TEST(SpeedSvg, WindowIsWhereTheSlowCurveLosesMost) {
  SpeedCurve fast{"fast", "blue", 1, false, {0, 100}, {100, 100}, true};
  // Half the speed from 60 to 70 mm: 0.1 s lost there.
  SpeedCurve slow{"slow", "red", 1, false, {0, 60, 60, 70, 70, 100}, {100, 100, 50, 50, 100, 100},
                  true};
  const Window w = slowest_window(slow, fast, 10, 1);
  EXPECT_DOUBLE_EQ(w.from, 60);
  EXPECT_DOUBLE_EQ(w.to, 70);
  const Window whole = slowest_window(slow, fast, 200, 1);  // longer than the curves
  EXPECT_DOUBLE_EQ(whole.from, 0);
  EXPECT_DOUBLE_EQ(whole.to, 200);
}

TEST(SpeedSvg, CurveOffTheScaleLeavesTheSpeedAxisToTheOthers) {
  const SpeedCurve speed{"cncd", "red", 1, false, {0, 10, 20}, {0, 140, 0}, true};
  const SpeedCurve feed{"feed", "grey", 1, true, {0, 20}, {75000, 75000}, false};
  const std::string svg = speed_svg({feed, speed}, {0, 20}, "title");
  EXPECT_NE(svg.find(">150</text>"), std::string::npos);  // the top tick fits 140 mm/s
  EXPECT_EQ(svg.find(">75000</text>"), std::string::npos);
  EXPECT_NE(svg.find("path length s (mm)"), std::string::npos);
  EXPECT_NE(svg.find(">feed</text>"), std::string::npos);  // in the legend
  std::size_t polylines = 0;
  for (auto at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1))
    ++polylines;
  EXPECT_EQ(polylines, 2u);
}

TEST(SpeedSvg, TitleAndLabelsAreEscaped) {
  const SpeedCurve speed{"a<b & \"c\"", "red", 1, false, {0, 10, 20}, {0, 140, 0}, true};
  const std::string svg = speed_svg({speed}, {0, 20}, "<part>.ngc & co");
  EXPECT_NE(svg.find(">&lt;part&gt;.ngc &amp; co</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">a&lt;b &amp; &quot;c&quot;</text>"), std::string::npos) << svg;
  EXPECT_EQ(svg.find("<part>"), std::string::npos);
}

TEST(SpeedSvg, ReferenceProfileRampsAtTheAccelerationLimit) {
  motion::Segment line;
  line.kind = motion::Segment::Kind::line;
  line.end[0] = 100;
  line.length = 100;
  line.feed = 200;  // reached after 10 mm at 2000 mm/s^2
  ReferenceOptions options;
  options.profile = true;
  const auto r = time_optimal(three_axis_mill(), {line}, options);
  ASSERT_GT(r.profile.size(), 4u);
  EXPECT_DOUBLE_EQ(r.profile.front().s, 0);
  EXPECT_DOUBLE_EQ(r.profile.back().s, 100);
  EXPECT_DOUBLE_EQ(r.profile.back().v, 0);
  double top = 0, t = 0;
  for (std::size_t k = 0; k < r.profile.size(); ++k) {
    const auto& p = r.profile[k];
    top = std::max(top, p.v);
    const double ramp = std::min(p.s, 100 - p.s);
    if (ramp < 10) {
      EXPECT_NEAR(p.v, std::sqrt(2 * 2000 * ramp), 1e-6) << p.s;
    }
    if (k > 0) t += 2 * (p.s - r.profile[k - 1].s) / (p.v + r.profile[k - 1].v);
  }
  EXPECT_DOUBLE_EQ(top, 200);
  EXPECT_NEAR(t, r.time_s, 0.02 * r.time_s);  // 8 points a ramp: within 2 % of 0.6 s
}

}  // namespace
}  // namespace cncd::bench
