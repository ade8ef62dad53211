// The MPG in velocity mode, in virtual time: the wheel's speed is the jog speed, a wheel that
// stops stops the axis under its deceleration limit without catching up, soft limits hold.
#include <cmath>

#include <gtest/gtest.h>

#include "panel_fixture.hpp"

namespace cncd::test::panel {
namespace {

using motion::MotionState;

constexpr auto kVelocity = PanelConfig::MpgMode::velocity;

// Turns the wheel `per_period` counts each period for `periods`.
void spin(PanelRig& rig, int per_period, int periods) {
  for (int i = 0; i < periods; ++i) {
    rig.drive.turn(per_period);
    rig.m.cycles(1);
  }
}

TEST(PanelMpgVelocity, AFastSpinThatStopsStopsWithinTheDecelerationDistance) {
  PanelRig rig(panel_mill(kVelocity, 4));
  rig.select(0, 2);  // 0.1 a detent
  const motion::AxisPose start = rig.m.status().commanded;
  rig.m.clear_trajectory();
  // 3 counts a period at 4 a detent: 750 detents/s x 0.1 = 75 mm/s.
  spin(rig, 3, 400);
  const motion::Status at_stop = rig.m.status();
  EXPECT_TRUE(at_stop.panel.mpg_jogging);
  EXPECT_NEAR(at_stop.velocity, 75, 1e-6);
  const double v = at_stop.velocity;
  const double a = rig.config.axes[0].max_acceleration;
  const double x0 = at_stop.commanded[0];
  // 400 ms of the wheel: 30 mm counted; the axis lags behind the wheel by its start.
  EXPECT_LT(x0, 30);
  rig.m.run_until_idle();
  const double x_end = rig.m.status().commanded[0];
  // v^2 / 2a = 1.406 mm, and the two quiet periods it takes to see the wheel has stopped.
  const double allowed = v * v / (2 * a) + 2 * v * rig.m.period_s();
  EXPECT_LE(x_end - x0, allowed + 1e-9);
  EXPECT_GE(x_end - x0, v * v / (2 * a) - 1e-9);
  expect_within_limits(rig.m, start);
  // Never caught up: it stays where it stopped.
  rig.m.cycles(2000);
  EXPECT_EQ(rig.m.status().commanded[0], x_end);
  EXPECT_FALSE(rig.m.status().panel.mpg_jogging);
  EXPECT_EQ(rig.m.status().motion, MotionState::idle);
}

TEST(PanelMpgVelocity, SpeedIsCappedAtMaxVelocityAndFollowsTheSign) {
  PanelRig rig(panel_mill(kVelocity, 1));
  rig.select(1, 2);
  spin(rig, -10, 600);  // 1000 mm/s asked of Y's 200
  EXPECT_NEAR(rig.m.status().velocity, 200, 1e-6);
  EXPECT_LT(rig.m.status().commanded[1], -50);
  // A slow wheel: one count every 10 periods at 1 a detent, 0.01 each: 1 mm/s.
  rig.m.run_until_idle();
  rig.select(1, 1);
  const double y0 = rig.m.status().commanded[1];
  for (int i = 0; i < 100; ++i) {
    rig.drive.turn(1);
    rig.m.cycles(10);
  }
  EXPECT_NEAR(rig.m.status().velocity, 1, 0.2);
  rig.m.run_until_idle();
  EXPECT_NEAR(rig.m.status().commanded[1] - y0, 1, 0.1);
}

TEST(PanelMpgVelocity, ASpinTowardASoftLimitStopsAtTheLimit) {
  config::MachineConfig c = panel_mill(kVelocity, 1);
  c.axes[0].max_limit = 20;
  PanelRig rig(c);
  rig.select(0, 2);
  rig.m.clear_trajectory();
  spin(rig, 1, 1000);  // 100 mm/s for 1 s toward 20
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], 20);
  for (const auto& pose : rig.m.trajectory())
    EXPECT_LE(pose[0], 20);
  expect_within_limits(rig.m, {});
  spin(rig, 1, 100);  // at the limit: nowhere to go
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], 20);
  spin(rig, -1, 100);  // away from it: moves
  rig.m.run_until_idle();
  EXPECT_LT(rig.m.status().commanded[0], 19);
}

TEST(PanelMpgVelocity, CountsInEstopAreDropped) {
  PanelRig rig(panel_mill(kVelocity, 1));
  rig.select(0, 2);
  rig.m.command(motion::Command::Kind::estop);
  spin(rig, 5, 100);
  rig.m.command(motion::Command::Kind::reset_estop);
  rig.m.command(motion::Command::Kind::on);
  rig.m.cycles(200);
  EXPECT_EQ(rig.m.status().commanded[0], 0);
}

}  // namespace
}  // namespace cncd::test::panel
