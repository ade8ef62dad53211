// Jogging in the servo loop, in virtual time: limits respected, soft limits reached exactly,
// controlled stops, refusals.
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MotionState;

void jog(VirtualMachine& m, Command::Kind kind, int axis, double velocity, double distance = 0) {
  send_jog(m, kind, axis, velocity, distance);
}

// Peak speed and acceleration of `axis` over the recorded trajectory.
void peaks(const VirtualMachine& m, int axis, double& v_peak, double& a_peak) {
  const auto& t = m.trajectory();
  const double dt = m.period_s();
  v_peak = 0;
  a_peak = 0;
  const auto k = static_cast<std::size_t>(axis);
  for (std::size_t i = 1; i < t.size(); ++i) {
    v_peak = std::max(v_peak, std::abs(t[i][k] - t[i - 1][k]) / dt);
    if (i >= 2)
      a_peak = std::max(a_peak, std::abs(t[i][k] - 2 * t[i - 1][k] + t[i - 2][k]) / (dt * dt));
  }
}

TEST(Jog, ContinuousJogKeepsTheLimitsAndStopsUnderControl) {
  VirtualMachine m(small_mill());
  m.ready();
  jog(m, Command::Kind::jog_start, 0, 500);  // above MAX_VELOCITY 200: capped
  m.cycles(1000);
  EXPECT_EQ(m.status().motion, MotionState::jogging);
  EXPECT_NEAR(m.status().velocity, 200, 1e-9);
  const double at_stop = m.status().commanded[0];
  jog(m, Command::Kind::jog_stop, 0, 0);
  m.run_until_idle();
  // 200 mm/s at 2000 mm/s^2 comes to rest in 10 mm.
  EXPECT_NEAR(m.status().commanded[0] - at_stop, 10, 0.25);
  EXPECT_EQ(m.status().motion, MotionState::idle);
  double v = 0, a = 0;
  peaks(m, 0, v, a);
  EXPECT_LE(v, 200 * (1 + 1e-9));
  EXPECT_LE(a, 2000 * (1 + 1e-6));
  EXPECT_GT(a, 1900);
  EXPECT_EQ(m.status().commanded[1], 0);  // other axes stay
}

TEST(Jog, StopsExactlyAtTheSoftLimitOfAHomedAxis) {
  VirtualMachine m(small_mill());
  m.ready();
  jog(m, Command::Kind::jog_start, 2, 100);  // Z: 100 mm/s, max limit 500
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[2], 500.0);
  for (const auto& pose : m.trajectory())
    EXPECT_LE(pose[2], 500.0);
  double v = 0, a = 0;
  peaks(m, 2, v, a);
  EXPECT_LE(v, 100 * (1 + 1e-9));
  EXPECT_LE(a, 1000 * (1 + 1e-6));
  // Further on is refused; back is fine.
  drain_events(m);
  jog(m, Command::Kind::jog_start, 2, 10);
  EXPECT_NE(drain_events(m).find("maximum soft limit"), std::string::npos);
  EXPECT_EQ(m.status().motion, MotionState::idle);
  jog(m, Command::Kind::jog_increment, 2, 50, -20);
  m.run_until_idle();
  EXPECT_NEAR(m.status().commanded[2], 480.0, 1e-9);
}

TEST(Jog, IncrementMovesTheDistanceWithinTheSpeedAndClipsAtTheLimit) {
  VirtualMachine m(small_mill());
  m.ready();
  jog(m, Command::Kind::jog_increment, 1, 50, -12.5);
  m.run_until_idle();
  EXPECT_NEAR(m.status().commanded[1], -12.5, 1e-9);
  double v = 0, a = 0;
  peaks(m, 1, v, a);
  EXPECT_LE(v, 50 * (1 + 1e-9));
  EXPECT_GT(v, 49);
  jog(m, Command::Kind::jog_increment, 1, 200, -2000);
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[1], -1000.0);
}

TEST(Jog, ReversingComesToRestFirst) {
  VirtualMachine m(small_mill());
  m.ready();
  jog(m, Command::Kind::jog_start, 0, 100);
  m.cycles(500);
  jog(m, Command::Kind::jog_start, 0, -100);
  m.cycles(1000);
  EXPECT_EQ(m.status().motion, MotionState::jogging);
  EXPECT_NEAR(m.status().velocity, 100, 1e-9);
  jog(m, Command::Kind::jog_stop, 0, 0);
  m.run_until_idle();
  double v = 0, a = 0;
  peaks(m, 0, v, a);
  EXPECT_LE(v, 100 * (1 + 1e-9));
  EXPECT_LE(a, 2000 * (1 + 1e-6));
}

TEST(Jog, UnhomedAxisJogsWithoutSoftLimits) {
  VirtualMachine m(small_mill());
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  jog(m, Command::Kind::jog_increment, 2, 100, -600);
  m.run_until_idle();
  EXPECT_NEAR(m.status().commanded[2], -600, 1e-9);
}

TEST(Jog, RefusedWhenOffOrWhilePathMotionRuns) {
  VirtualMachine m(small_mill());
  m.command(Command::Kind::reset_estop);
  jog(m, Command::Kind::jog_start, 0, 10);
  EXPECT_NE(drain_events(m).find("jog ignored: the machine is not on"), std::string::npos);
  EXPECT_EQ(m.status().motion, MotionState::idle);
  m.command(Command::Kind::on);
  m.command(Command::Kind::home, 0xFFFFFFFFu);
  m.run_until_idle();
  m.queue(line_to(motion::Move::Kind::feed, 100, 0, 0, 50));
  m.cycles(10);
  drain_events(m);
  jog(m, Command::Kind::jog_start, 1, 10);
  EXPECT_NE(drain_events(m).find("the machine is moving"), std::string::npos);
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[1], 0);
}

TEST(Jog, EstopStopsAtOnceAndAbortUnderControl) {
  VirtualMachine m(small_mill());
  m.ready();
  jog(m, Command::Kind::jog_start, 0, 200);
  m.cycles(500);
  ASSERT_TRUE(m.loop().commands().push(Command{Command::Kind::abort, 0}));  // recorded cycles
  m.run_until_idle();
  double v = 0, a = 0;
  peaks(m, 0, v, a);
  EXPECT_LE(a, 2000 * (1 + 1e-6));
  jog(m, Command::Kind::jog_start, 0, 200);
  m.cycles(500);
  m.command(Command::Kind::estop);
  const double held = m.status().commanded[0];
  m.cycles(100);
  EXPECT_EQ(m.status().motion, MotionState::idle);
  EXPECT_EQ(m.status().commanded[0], held);
}

}  // namespace
}  // namespace cncd::test
