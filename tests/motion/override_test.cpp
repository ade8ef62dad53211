// Feed and rapid overrides in virtual time: they scale the programmed speed, change it on the
// move under way within the acceleration limits, and never lift an axis past its limits.
#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MotionState;
using motion::Move;

void set_override(VirtualMachine& m, Command::Kind kind, double ratio) {
  Command command;
  command.kind = kind;
  command.velocity = ratio;
  ASSERT_TRUE(m.loop().commands().push(command));
  m.cycles(1);
}

// Largest X speed and acceleration (finite differences of the recorded periods).
struct XPeaks {
  double velocity = 0;
  double acceleration = 0;
};

XPeaks x_peaks(const VirtualMachine& m, std::size_t from = 1) {
  XPeaks peaks;
  const auto& t = m.trajectory();
  const double dt = m.period_s();
  for (std::size_t k = std::max<std::size_t>(from, 2); k < t.size(); ++k) {
    const double v = (t[k][0] - t[k - 1][0]) / dt;
    const double v_before = (t[k - 1][0] - t[k - 2][0]) / dt;
    peaks.velocity = std::max(peaks.velocity, std::abs(v));
    peaks.acceleration = std::max(peaks.acceleration, std::abs(v - v_before) / dt);
  }
  return peaks;
}

config::MachineConfig mill_with_override(double max_feed_override) {
  auto config = small_mill();
  config.max_feed_override = max_feed_override;
  return config;
}

TEST(Override, FeedOverrideScalesTheFeedButNotTheAxisLimit) {
  VirtualMachine m(mill_with_override(2.0));
  m.ready();
  set_override(m, Command::Kind::feed_override, 2.0);
  EXPECT_DOUBLE_EQ(m.status().feed_override, 2.0);
  m.clear_trajectory();
  m.queue(line_to(Move::Kind::feed, 200, 0, 0, 50));  // 50 mm/s x 2
  m.run_until_idle();
  EXPECT_NEAR(x_peaks(m).velocity, 100, 0.1);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 200);

  m.clear_trajectory();
  m.queue(line_to(Move::Kind::feed, 600, 0, 0, 150));  // 300 mm/s asked, X allows 200
  m.run_until_idle();
  const auto peaks = x_peaks(m);
  EXPECT_LE(peaks.velocity, 200 * 1.001);
  EXPECT_GT(peaks.velocity, 199);
  EXPECT_LE(peaks.acceleration, 2000 * 1.001);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 600);
}

TEST(Override, LoweringItSlowsTheMoveUnderWayWithinTheAccelerationLimit) {
  VirtualMachine m(mill_with_override(1.2));
  m.ready();
  m.clear_trajectory();
  m.queue(line_to(Move::Kind::feed, 300, 0, 0, 150));
  m.cycles(300);  // cruising at 150 mm/s
  set_override(m, Command::Kind::feed_override, 0.2);
  m.cycles(200);
  EXPECT_NEAR(m.status().velocity, 30, 1e-9);
  set_override(m, Command::Kind::feed_override, 0);  // a stop on the path
  m.cycles(100);
  const auto held = m.status();
  EXPECT_EQ(held.velocity, 0);
  EXPECT_EQ(held.motion, MotionState::moving);
  EXPECT_GT(held.distance_to_go, 0);
  EXPECT_NEAR(held.distance_to_go, 300 - held.commanded[0], 1e-9);
  EXPECT_NEAR(held.axes_to_go[0], 300 - held.commanded[0], 1e-9);
  EXPECT_EQ(held.axes_to_go[1], 0);
  m.cycles(100);
  EXPECT_EQ(m.status().commanded, held.commanded);
  set_override(m, Command::Kind::feed_override, 1.2);
  m.run_until_idle();
  const auto peaks = x_peaks(m);
  EXPECT_LE(peaks.acceleration, 2000 * 1.001);
  EXPECT_LE(peaks.velocity, 180 * 1.001);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 300);
  EXPECT_EQ(m.status().distance_to_go, 0);
}

TEST(Override, RapidOverrideScalesTraversesOnly) {
  VirtualMachine m(small_mill());
  m.ready();
  set_override(m, Command::Kind::rapid_override, 0.25);
  m.clear_trajectory();
  m.queue(line_to(Move::Kind::traverse, 200, 0, 0));
  m.run_until_idle();
  EXPECT_NEAR(x_peaks(m).velocity, 50, 0.1);
  m.clear_trajectory();
  m.queue(line_to(Move::Kind::feed, 400, 0, 0, 100));  // the feed keeps its speed
  m.run_until_idle();
  EXPECT_NEAR(x_peaks(m).velocity, 100, 0.1);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 400);
}

TEST(Override, RatiosAreClampedAndNonFiniteOnesIgnored) {
  VirtualMachine m(mill_with_override(1.5));
  m.ready();
  EXPECT_DOUBLE_EQ(m.status().feed_override, 1.0);
  EXPECT_DOUBLE_EQ(m.status().rapid_override, 1.0);
  set_override(m, Command::Kind::feed_override, 3.0);
  EXPECT_DOUBLE_EQ(m.status().feed_override, 1.5);
  set_override(m, Command::Kind::rapid_override, 2.0);
  EXPECT_DOUBLE_EQ(m.status().rapid_override, 1.0);
  set_override(m, Command::Kind::feed_override, -1);
  EXPECT_DOUBLE_EQ(m.status().feed_override, 0);
  set_override(m, Command::Kind::feed_override, std::numeric_limits<double>::quiet_NaN());
  EXPECT_DOUBLE_EQ(m.status().feed_override, 0);
  set_override(m, Command::Kind::rapid_override, std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(m.status().rapid_override, 1.0);
}

}  // namespace
}  // namespace cncd::test
