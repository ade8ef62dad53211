// The spindle the servo loop carries out with the path, in virtual time: at-speed before feed
// moves, its speed clamped and overridden, its drive's faults, STOP_ON_PAUSE, and a machine
// without one.
#include <cmath>

#include <gtest/gtest.h>

#include "machine_io_fixture.hpp"

namespace cncd::test {
namespace {

using namespace machine_io;

TEST(MachineIo, FeedWaitsForTheSpindleToReachSpeed) {
  Rig rig(mill_with_spindle(3000));
  auto& m = rig.m;
  m.queue(line_to(Move::Kind::traverse, 0, 0, 5, 0));
  m.queue(action(spindle(1, 3000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 0, 0, -1, 100.0 / 60.0));
  m.flush();
  double rpm_at_first_feed = -1;
  bool waited = false;
  for (int i = 0; i < 20000; ++i) {
    m.cycles(1);
    const auto s = m.status();
    if (s.wait.kind == WaitStatus::Kind::spindle_at_speed) waited = true;
    if (rpm_at_first_feed < 0 && s.commanded[2] < 5 - 1e-9 && s.line == 0 && waited) {
      rpm_at_first_feed = s.spindle.actual_rpm;
    }
    if (s.motion == MotionState::idle && s.queued == 0) break;
  }
  EXPECT_TRUE(waited);
  // 5 % of 3000 rpm: the feed starts at 2850 rpm or more, about 0.95 s after M3.
  EXPECT_GE(rpm_at_first_feed, 2850);
  const auto s = m.status();
  EXPECT_EQ(s.commanded[2], -1);
  EXPECT_TRUE(s.spindle.enabled);
  EXPECT_EQ(s.spindle.direction, 1);
  EXPECT_EQ(s.spindle.commanded_rpm, 3000);
  EXPECT_TRUE(s.spindle.at_speed);
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::none);
}

// The status of the period the spindle is told to turn is whole: turning at 0 rpm, not yet at
// speed (a client that reads it then must not see a spindle at speed at 0 rpm).
TEST(MachineIo, TheSpindleIsNotAtSpeedInThePeriodItIsStarted) {
  Rig rig(mill_with_spindle(3000));
  auto& m = rig.m;
  ASSERT_TRUE(m.status().spindle.at_speed);  // stopped, and so at its speed
  m.queue(action(spindle(1, 3000)));
  m.flush();
  for (int i = 0; i < 100 && !m.status().spindle.enabled; ++i)
    m.cycles(1);
  const auto s = m.status();
  ASSERT_TRUE(s.spindle.enabled);
  EXPECT_EQ(s.spindle.actual_rpm, 0);
  EXPECT_FALSE(s.spindle.at_speed);
}

TEST(MachineIo, ATraverseDoesNotWaitForTheSpindle) {
  Rig rig(mill_with_spindle(100));  // 30 s to 3000 rpm
  auto& m = rig.m;
  m.queue(action(spindle(1, 3000)));
  m.queue(line_to(Move::Kind::traverse, 10, 0, 0, 0));
  const int cycles = m.run_until_idle();
  EXPECT_LT(cycles, 1000);
  EXPECT_EQ(m.status().commanded[0], 10);
  EXPECT_LT(m.status().spindle.actual_rpm, 200);
}

TEST(MachineIo, ASpindleThatNeverGetsThereStopsTheProgramNotTheMachine) {
  Rig rig(mill_with_spindle(1000, 0.5));  // 3 s to 3000 rpm, 0.5 s allowed
  auto& m = rig.m;
  m.queue(action(spindle(1, 3000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 0, 0, -1, 10));
  m.queue(line_to(Move::Kind::feed, 5, 0, -1, 10));
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.path_errors, 1u);
  EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::spindle_not_at_speed);
  const std::string words = motion::format_event(s.path_error);
  EXPECT_NE(words.find("spindle 0 did not reach 3000 rpm within 0.5 s"), std::string::npos)
      << words;
  EXPECT_EQ(s.machine, MachineState::on);
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_EQ(s.commanded[2], 0);  // the feed never started
  EXPECT_EQ(s.queued, 0u);
}

TEST(MachineIo, SpeedIsClampedAndOverriddenLive) {
  Rig rig(mill_with_spindle(0));
  auto& m = rig.m;
  m.queue(action(spindle(1, 30000)));
  m.run_until_idle();
  EXPECT_EQ(m.status().spindle.commanded_rpm, 24000);
  m.queue(action(spindle(-1, 20000)));
  m.run_until_idle();
  EXPECT_EQ(m.status().spindle.commanded_rpm, 12000);
  EXPECT_TRUE(rig.m.io_trajectory().back().spindle.reverse);
  m.queue(action(spindle(1, 1000)));
  m.run_until_idle();
  Command c;
  c.kind = Command::Kind::spindle_override;
  c.velocity = 1.5;
  m.send(c);
  EXPECT_EQ(m.status().spindle.commanded_rpm, 1500);
  EXPECT_EQ(rig.m.io_trajectory().back().spindle.rpm, 1500);
  // M51 P0 / M49: the override no longer applies.
  IoAction off = of_kind(IoAction::Kind::spindle_override_enable);
  off.on = false;
  m.queue(action(off));
  m.run_until_idle();
  EXPECT_EQ(m.status().spindle.commanded_rpm, 1000);
  EXPECT_FALSE(m.status().spindle.override_enabled);
}

TEST(MachineIo, ASpindleDriveFaultFaultsTheMachineInTheDriversWords) {
  Rig rig(mill_with_spindle(0));
  auto& m = rig.m;
  m.queue(action(spindle(1, 1000)));
  m.run_until_idle();
  rig.drive.fault_ = true;
  m.cycles(1);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_STREQ(s.fault_reason, "spindle 0: drive fault: VFD reports overcurrent");
}

TEST(MachineIo, StopOnPauseRestartsTheSpindleAndWaitsBeforeGoingOn) {
  config::MachineConfig config = mill_with_spindle(2000);
  config.spindle.stop_on_pause = true;
  Rig rig(config);
  auto& m = rig.m;
  m.queue(action(spindle(1, 2000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 100, 0, 0, 20));
  m.flush();
  m.cycles(2000);
  ASSERT_GT(m.status().commanded[0], 0);
  m.command(Command::Kind::pause);
  m.cycles(1500);
  auto s = m.status();
  EXPECT_EQ(s.motion, MotionState::paused);
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_TRUE(s.spindle.paused_off);
  EXPECT_EQ(rig.drive.rpm(), 0);
  const double x = s.commanded[0];
  m.command(Command::Kind::resume);
  m.cycles(500);  // 2000 rpm/s: at 1900 rpm after 0.95 s
  s = m.status();
  EXPECT_TRUE(s.spindle.enabled);
  EXPECT_EQ(s.commanded[0], x);
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::spindle_at_speed);
  m.cycles(700);
  EXPECT_GT(m.status().commanded[0], x);
}

TEST(MachineIo, StartingASpindleTheMachineLacksStopsTheProgram) {
  config::MachineConfig config = mill_with_spindle();
  config.spindle.driver = config::SpindleDriver::none;
  Rig rig(config);
  auto& m = rig.m;
  m.queue(action(spindle(1, 1000)));
  m.queue(line_to(Move::Kind::traverse, 10, 0, 0, 0));
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.path_errors, 1u);
  EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::no_spindle);
  EXPECT_EQ(s.commanded[0], 0);
}

TEST(MachineIo, WithoutASpindleSectionTheSpindleIsAtSpeedAtOnce) {
  config::MachineConfig config = small_mill();
  Rig rig(config);
  auto& m = rig.m;
  m.queue(action(spindle(1, 5000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 10, 0, 0, 100));
  const int cycles = m.run_until_idle();
  EXPECT_LT(cycles, 200);
  EXPECT_EQ(m.status().spindle.actual_rpm, 5000);
}

}  // namespace
}  // namespace cncd::test
