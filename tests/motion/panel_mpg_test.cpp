// The MPG in position mode and the panel's part of the servo loop, in virtual time: detents
// moved exactly, counts dropped when the MPG may not move, one hand on the machine, lights.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "panel_fixture.hpp"

namespace cncd::test::panel {
namespace {

using motion::Command;
using motion::MachineState;
using motion::MotionState;

constexpr auto kPosition = PanelConfig::MpgMode::position;

void send(VirtualMachine& m, Command::Kind kind, int axis = 0, double velocity = 0,
          std::uint32_t id = 0) {
  Command c;
  c.kind = kind;
  c.axis = axis;
  c.velocity = velocity;
  c.id = id;
  m.send(c);
}

TEST(PanelMpg, FourHundredCountsAtOneHundredPerDetentMoveXByExactlyStep) {
  PanelRig rig(panel_mill(kPosition, 100));
  rig.select(0, 1);  // X, 0.01 a detent
  const double x0 = rig.m.status().commanded[0];
  rig.drive.turn(400);
  rig.m.cycles(1);
  EXPECT_TRUE(rig.m.status().panel.mpg_jogging);
  EXPECT_EQ(rig.m.status().motion, MotionState::jogging);
  rig.m.run_until_idle();
  EXPECT_FALSE(rig.m.status().panel.mpg_jogging);
  EXPECT_EQ(rig.m.status().commanded[0], x0 + 4 * 0.01);
  EXPECT_EQ(rig.m.status().panel.counts[0], 400);
  EXPECT_EQ(rig.m.status().commanded[1], 0);
}

TEST(PanelMpg, BurstsSumExactlyWhileMovingAndFractionsCarry) {
  PanelRig rig(panel_mill(kPosition, 100));
  rig.select(0, 2);  // 0.1 a detent
  const double x0 = rig.m.status().commanded[0];
  // 1234 counts in bursts of 37 every 3 periods, most of them while the axis moves.
  std::int64_t sent = 0;
  while (sent < 1234) {
    const std::int64_t n = std::min<std::int64_t>(37, 1234 - sent);
    rig.drive.turn(n);
    sent += n;
    rig.m.cycles(3);
  }
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], x0 + 12 * 0.1);  // 34 counts short of a 13th
  rig.drive.turn(66);
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], x0 + 13 * 0.1);
}

TEST(PanelMpg, RandomBurstsEndOnTheSummedDetentsWithinTheLimits) {
  for (const unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    SCOPED_TRACE(seed);
    std::mt19937 rng(seed);
    PanelRig rig(panel_mill(kPosition, 4));
    rig.select(1, 2);  // Y, 0.1 a detent
    const motion::AxisPose start = rig.m.status().commanded;
    rig.m.clear_trajectory();
    std::uniform_int_distribution<int> burst(-400, 600);
    std::uniform_int_distribution<int> gap(0, 60);
    std::int64_t sum = 0;
    for (int i = 0; i < 60; ++i) {
      const int n = burst(rng);
      rig.drive.turn(n);
      sum += n;
      rig.m.cycles(1 + gap(rng));
    }
    rig.m.run_until_idle();
    const std::int64_t detents = sum >= 0 ? sum / 4 : -((-sum + 3) / 4);  // floor
    EXPECT_EQ(rig.m.status().commanded[1], start[1] + static_cast<double>(detents) * 0.1);
    expect_within_limits(rig.m, start);
  }
}

TEST(PanelMpg, AStepChangedMidMoveKeepsEachDetentsDistance) {
  PanelRig rig(panel_mill(kPosition, 1));
  rig.select(2, 2);  // Z, 0.1 a detent
  rig.drive.turn(30);
  rig.m.cycles(5);
  rig.select(2, 0);  // 0.001 a detent from now on
  rig.drive.turn(7);
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[2], 30 * 0.1 + 7 * 0.001);
}

TEST(PanelMpg, AClientStopHoldsTheMpgAndDropsItsTarget) {
  PanelRig rig(panel_mill(kPosition, 1));
  rig.select(0, 2);
  rig.drive.turn(500);  // 50 mm
  rig.m.cycles(100);
  ASSERT_TRUE(rig.m.status().panel.mpg_jogging);
  send(rig.m, Command::Kind::jog_stop, 0);
  rig.m.run_until_idle();
  const double held = rig.m.status().commanded[0];
  EXPECT_LT(held, 50);
  rig.m.cycles(200);
  EXPECT_EQ(rig.m.status().commanded[0], held);
  rig.drive.turn(1);  // the next detent moves from where it stopped
  rig.m.run_until_idle();
  EXPECT_NEAR(rig.m.status().commanded[0], held + 0.1, 1e-12);
}

TEST(PanelMpg, AnotherAxisSelectedMidMoveStopsTheFirstAndWaitsForIt) {
  PanelRig rig(panel_mill(kPosition, 1));
  rig.select(0, 2);
  rig.drive.turn(500);
  rig.m.cycles(100);
  rig.select(1, 2);
  rig.drive.turn(10);  // while X comes to rest: dropped
  rig.m.run_until_idle();
  EXPECT_LT(rig.m.status().commanded[0], 50);
  EXPECT_EQ(rig.m.status().commanded[1], 0);
  rig.drive.turn(10);
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[1], 10 * 0.1);
}

TEST(PanelMpg, AHomedAxisStopsAtItsSoftLimit) {
  config::MachineConfig c = panel_mill(kPosition, 1);
  c.axes[0].max_limit = 3;
  PanelRig rig(c);
  rig.select(0, 2);
  rig.drive.turn(100);  // 10 mm asked, 3 allowed
  rig.m.clear_trajectory();
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], 3);
  for (const auto& pose : rig.m.trajectory())
    EXPECT_LE(pose[0], 3);
  rig.drive.turn(-5);  // turning back leaves the limit at once: the excess is not owed
  rig.m.run_until_idle();
  EXPECT_NEAR(rig.m.status().commanded[0], 2.5, 1e-12);
}

TEST(PanelMpg, CountsInEstopOffOrDuringPathMotionAreDropped) {
  PanelRig rig(panel_mill(kPosition, 100));
  rig.select(0, 1);
  const double x0 = rig.m.status().commanded[0];
  rig.m.command(Command::Kind::estop);
  rig.drive.turn(500);
  rig.m.cycles(10);
  rig.m.command(Command::Kind::reset_estop);
  rig.drive.turn(500);  // machine off
  rig.m.cycles(10);
  rig.m.command(Command::Kind::on);
  rig.m.cycles(50);
  EXPECT_EQ(rig.m.status().commanded[0], x0);
  // During a move of Y the wheel turns: nothing is queued for later.
  rig.m.queue(line_to(motion::Move::Kind::traverse, x0, 50, 0));
  rig.m.flush();
  rig.m.cycles(20);
  ASSERT_EQ(rig.m.status().motion, MotionState::moving);
  rig.drive.turn(700);
  rig.m.cycles(5);
  rig.m.run_until_idle();
  rig.m.cycles(100);
  EXPECT_EQ(rig.m.status().commanded[0], x0);
  // MPG disabled, or no axis selected: dropped too.
  rig.drive.inputs = mpg_axis_bit(0);
  rig.m.cycles(1);
  rig.drive.turn(300);
  rig.m.cycles(10);
  rig.drive.inputs = bit(PanelInput::mpg_enable);
  rig.m.cycles(1);
  rig.drive.turn(300);
  rig.m.cycles(10);
  rig.select(0, 1);
  rig.m.cycles(100);
  EXPECT_EQ(rig.m.status().commanded[0], x0);
  rig.drive.turn(100);  // and the next detent moves one detent
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[0], x0 + 0.01);
}

TEST(PanelMpg, AClientJogIsRefusedWhileTheMpgMovesAndTheMpgWaitsForAClientJog) {
  PanelRig rig(panel_mill(kPosition, 1));
  rig.select(0, 2);
  drain_events(rig.m);
  rig.drive.turn(500);  // 50 mm: a while
  rig.m.cycles(10);
  ASSERT_TRUE(rig.m.status().panel.mpg_jogging);
  send(rig.m, Command::Kind::jog_start, 1, 50);
  send(rig.m, Command::Kind::jog_increment, 2, 50);
  const std::string events = drain_events(rig.m);
  EXPECT_NE(events.find("the panel's MPG"), std::string::npos) << events;
  rig.m.run_until_idle();
  EXPECT_EQ(rig.m.status().commanded[1], 0);
  EXPECT_EQ(rig.m.status().commanded[2], 0);
  const double x = rig.m.status().commanded[0];
  EXPECT_EQ(x, 50);

  // The other way: counts while a client jogs Y are dropped.
  send(rig.m, Command::Kind::jog_start, 1, 50);
  rig.drive.turn(200);
  rig.m.cycles(100);
  send(rig.m, Command::Kind::jog_stop, 1);
  rig.m.run_until_idle();
  rig.m.cycles(100);
  EXPECT_EQ(rig.m.status().commanded[0], x);
  EXPECT_FALSE(rig.m.status().panel.mpg_jogging);
}

TEST(PanelMpg, LightsAreTheTasksWithRedInEstopOrAFault) {
  PanelRig rig(panel_mill(kPosition, 4));
  const std::uint32_t red = 1u << static_cast<int>(config::PanelLight::red);
  const std::uint32_t green = 1u << static_cast<int>(config::PanelLight::green);
  send(rig.m, Command::Kind::panel_lights, 0, 0, green);
  EXPECT_EQ(rig.drive.lights, green);
  EXPECT_EQ(rig.m.io_trajectory().back().panel, green);
  EXPECT_EQ(rig.m.status().panel.lights, green);
  rig.m.command(Command::Kind::estop);
  EXPECT_EQ(rig.drive.lights, green | red);
  EXPECT_EQ(rig.m.status().panel.lights, green | red);
  rig.m.command(Command::Kind::reset_estop);
  rig.m.command(Command::Kind::on);
  EXPECT_EQ(rig.drive.lights, green);
  send(rig.m, Command::Kind::panel_lights, 0, 0, 0);
  EXPECT_EQ(rig.drive.lights, 0u);
}

}  // namespace
}  // namespace cncd::test::panel
