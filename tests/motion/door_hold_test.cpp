// The door's hold in the servo loop, in virtual time: once the path rests the spindle stops and
// the coolant goes off; the resume turns them on as they were and the path waits for the
// spindle's speed, also when it rested at an M0 with no move under way; without a program to
// resume they stay off.
#include <gtest/gtest.h>

#include "machine_io_fixture.hpp"

namespace cncd::test {
namespace {

using namespace machine_io;

IoAction flood_on() {
  IoAction a;
  a.kind = IoAction::Kind::coolant;
  a.flood = true;
  return a;
}

void hold_io(VirtualMachine& m, bool restore) {
  Command c;
  c.kind = Command::Kind::io_hold;
  c.id = restore ? 1 : 0;
  m.send(c);
}

TEST(DoorHold, TheSpindleAndCoolantStopAtRestAndResumeWaitsForTheSpeed) {
  Rig rig(mill_with_spindle(2000));
  auto& m = rig.m;
  m.queue(action(spindle(1, 2000)));
  m.queue(action(flood_on()));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 100, 0, 0, 20));
  m.flush();
  m.cycles(2000);
  ASSERT_GT(m.status().commanded[0], 0);
  m.command(Command::Kind::pause);
  hold_io(m, true);
  // Still decelerating: the spindle turns until the path rests.
  EXPECT_TRUE(m.status().spindle.enabled);
  m.cycles(1500);
  auto s = m.status();
  EXPECT_EQ(s.motion, MotionState::paused);
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_TRUE(s.spindle.paused_off);
  EXPECT_EQ(s.spindle.direction, 1);
  EXPECT_FALSE(s.io.flood);
  EXPECT_FALSE(m.io_trajectory().back().flood);
  EXPECT_EQ(rig.drive.rpm(), 0);
  const double x = s.commanded[0];
  m.command(Command::Kind::resume);
  EXPECT_TRUE(m.status().io.flood);
  m.cycles(500);  // 2000 rpm/s: below speed after 0.5 s
  s = m.status();
  EXPECT_TRUE(s.spindle.enabled);
  EXPECT_EQ(s.commanded[0], x);
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::spindle_at_speed);
  m.cycles(700);
  EXPECT_GT(m.status().commanded[0], x);
}

TEST(DoorHold, AfterAnM0TheResumedPathWaitsForTheSpindleBeforeItsNextMove) {
  Rig rig(mill_with_spindle(2000));
  auto& m = rig.m;
  m.queue(action(spindle(1, 2000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.queue(line_to(Move::Kind::feed, 10, 0, 0, 20));
  m.run_until_idle();
  ASSERT_EQ(m.status().motion, MotionState::idle);
  hold_io(m, true);
  m.cycles(1500);  // 2000 rpm/s: at rest after 1 s
  ASSERT_FALSE(m.status().spindle.enabled);
  ASSERT_EQ(rig.drive.rpm(), 0);
  m.command(Command::Kind::resume);
  m.queue(line_to(Move::Kind::feed, 20, 0, 0, 20));
  m.flush();
  m.cycles(500);
  auto s = m.status();
  EXPECT_TRUE(s.spindle.enabled);
  EXPECT_FALSE(s.spindle.at_speed);
  EXPECT_EQ(s.commanded[0], 10);
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[0], 20);
}

TEST(DoorHold, WithoutAProgramTheSpindleAndCoolantStayOff) {
  Rig rig(mill_with_spindle(2000));
  auto& m = rig.m;
  m.queue(action(spindle(1, 2000)));
  m.queue(action(flood_on()));
  m.run_until_idle();
  ASSERT_TRUE(m.status().spindle.enabled);
  hold_io(m, false);
  m.cycles(1);
  auto s = m.status();
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_EQ(s.spindle.direction, 0);
  EXPECT_FALSE(s.io.flood);
  m.command(Command::Kind::resume);
  m.cycles(10);
  s = m.status();
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_FALSE(s.io.flood);
}

}  // namespace
}  // namespace cncd::test
