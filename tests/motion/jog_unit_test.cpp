// Jogging alone: the jog's axis pose stepped period by period, without a servo loop.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/motion/jog.hpp"
#include "machine_fixture.hpp"

namespace cncd::motion {
namespace {

constexpr double kDt = 1e-3;

// X's positions, one a period, until no axis jogs or `max_periods`.
std::vector<double> run(Jog& jog, AxisPose& pose, int max_periods = 100'000) {
  std::vector<double> x;
  while (jog.active() && static_cast<int>(x.size()) < max_periods) {
    jog.update(pose, kDt);
    x.push_back(pose[0]);
  }
  return x;
}

TEST(JogUnit, ContinuousJogRunsAtItsSpeedUntilStopped) {
  const auto config = test::small_mill();
  Jog jog(config);
  AxisPose pose{};
  ASSERT_EQ(jog.start(0, 0.0, 500.0, false), nullptr);  // capped at X's 200 mm/s
  EXPECT_EQ(jog.active_mask(), 1u);
  const auto x = run(jog, pose, 300);
  EXPECT_NEAR(jog.speed(), 200.0, 1e-9);
  EXPECT_NEAR(x[299] - x[298], 200 * kDt, 1e-9);
  jog.stop(0);
  const double from = pose[0];
  run(jog, pose);
  EXPECT_FALSE(jog.active());
  // 200 mm/s stops within 200^2 / (2 * 2000) = 10 mm.
  EXPECT_NEAR(pose[0] - from, 10.0, 0.25);
}

TEST(JogUnit, HomedAxisStopsExactlyAtItsSoftLimit) {
  const auto config = test::small_mill();  // Z: -500 .. 500
  Jog jog(config);
  AxisPose pose{};
  pose[2] = 490;
  ASSERT_EQ(jog.start(2, 490.0, 100.0, true), nullptr);
  run(jog, pose);
  EXPECT_DOUBLE_EQ(pose[2], 500.0);
  EXPECT_STREQ(jog.start(2, 500.0, 100.0, true), "the axis is at its maximum soft limit");
  EXPECT_EQ(jog.start(2, 500.0, -100.0, true), nullptr);
}

TEST(JogUnit, IncrementMovesItsDistanceAndIsClippedAtTheLimit) {
  const auto config = test::small_mill();
  Jog jog(config);
  AxisPose pose{};
  ASSERT_EQ(jog.increment(0, 0.0, 2.5, 50.0, true), nullptr);
  const auto x = run(jog, pose);
  EXPECT_DOUBLE_EQ(pose[0], 2.5);
  for (std::size_t k = 1; k < x.size(); ++k)
    EXPECT_LE(x[k] - x[k - 1], 50 * kDt + 1e-12);
  pose[0] = 999;
  ASSERT_EQ(jog.increment(0, 999.0, 5.0, 50.0, true), nullptr);
  run(jog, pose);
  EXPECT_DOUBLE_EQ(pose[0], 1000.0);
}

TEST(JogUnit, RefusesAnAxisTheMachineLacks) {
  const auto config = test::small_mill();  // XYZ only
  Jog jog(config);
  EXPECT_STREQ(jog.start(3, 0.0, 10.0, false), "the machine has no such axis");
  EXPECT_FALSE(jog.active());
}

TEST(JogUnit, HaltForgetsEveryJogAtOnce) {
  const auto config = test::small_mill();
  Jog jog(config);
  AxisPose pose{};
  ASSERT_EQ(jog.start(0, 0.0, 100.0, false), nullptr);
  ASSERT_EQ(jog.start(1, 0.0, -100.0, false), nullptr);
  EXPECT_EQ(jog.active_mask(), 3u);
  run(jog, pose, 100);
  jog.halt();
  EXPECT_FALSE(jog.active());
  const AxisPose held = pose;
  jog.update(pose, kDt);
  EXPECT_EQ(pose, held);
}

}  // namespace
}  // namespace cncd::motion
