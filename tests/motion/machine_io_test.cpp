// The coolant, outputs and waits the servo loop carries out with the path, in virtual time:
// outputs with the start of a move, holds, M66 waits, and everything off on estop.
#include <cmath>

#include <gtest/gtest.h>

#include "machine_io_fixture.hpp"

namespace cncd::test {
namespace {

using namespace machine_io;

TEST(MachineIo, OutputsSetWithTheStartOfTheNextMoveExactToThePeriod) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  m.queue(line_to(Move::Kind::traverse, 10, 0, 0, 0));
  Move feed = line_to(Move::Kind::feed, 10, 10, 0, 50);
  feed.sync.set = 1u << 0;
  feed.sync.analog_mask = 1u << 2;
  feed.sync.analog[2] = 4.5;
  m.queue(feed);
  m.flush();
  int first_moving = -1, first_set = -1;
  for (int i = 0; i < 5000; ++i) {
    m.cycles(1);
    const auto s = m.status();
    if (first_moving < 0 && s.commanded[1] > 0) first_moving = i;
    if (first_set < 0 && (s.io.douts & 1u)) first_set = i;
    if (s.motion == MotionState::idle && s.queued == 0) break;
  }
  ASSERT_GE(first_set, 0);
  EXPECT_EQ(first_set, first_moving);
  EXPECT_EQ(m.status().io.aouts[2], 4.5);
  EXPECT_EQ(rig.m.io_trajectory().back().digital, 1u);
  EXPECT_EQ(rig.m.io_trajectory().back().analog[2], 4.5);
}

TEST(MachineIo, OutputsOfABlendedMoveGoWithTheBlendIntoIt) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  Move first = line_to(Move::Kind::feed, 10, 0, 0, 50);
  first.path_mode = Move::PathMode::blend;
  m.queue(first);
  Move second = line_to(Move::Kind::feed, 10, 10, 0, 50);
  second.path_mode = Move::PathMode::blend;
  second.sync.set = 1u << 3;
  m.queue(second);
  m.flush();
  double x_when_set = -1;
  for (int i = 0; i < 5000; ++i) {
    m.cycles(1);
    const auto s = m.status();
    if (x_when_set < 0 && (s.io.douts & (1u << 3))) x_when_set = s.commanded[0];
    if (s.motion == MotionState::idle && s.queued == 0) break;
  }
  // Set where the path leaves the first line for the corner's blend, before the corner.
  EXPECT_GT(x_when_set, 5);
  EXPECT_LE(x_when_set, 10);
}

TEST(MachineIo, ImmediateOutputsAndCoolantWaitForThePathToRest) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  m.queue(line_to(Move::Kind::feed, 20, 0, 0, 50));
  IoAction out = of_kind(IoAction::Kind::digital_output);
  out.index = 5;
  out.on = true;
  m.queue(action(out));
  IoAction coolant = of_kind(IoAction::Kind::coolant);
  coolant.flood = true;
  m.queue(action(coolant));
  m.flush();
  for (int i = 0; i < 5000; ++i) {
    m.cycles(1);
    const auto s = m.status();
    if (s.io.douts & (1u << 5)) {
      EXPECT_EQ(s.commanded[0], 20);
      break;
    }
  }
  m.run_until_idle();
  EXPECT_TRUE(m.status().io.flood);
  EXPECT_TRUE(rig.m.io_trajectory().back().flood);
}

TEST(MachineIo, AHoldWaitsForItsRelease) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  IoAction hold = of_kind(IoAction::Kind::hold);
  hold.hold = IoAction::Hold::tool_change;
  hold.hold_id = 7;
  m.queue(action(hold));
  m.queue(line_to(Move::Kind::traverse, 10, 0, 0, 0));
  m.flush();
  m.cycles(2000);
  auto s = m.status();
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::tool_change);
  EXPECT_EQ(s.wait.hold_id, 7u);
  EXPECT_EQ(s.commanded[0], 0);
  Command release;
  release.kind = Command::Kind::release;
  release.id = 6;  // another hold's answer does not release this one
  m.send(release);
  m.cycles(10);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::tool_change);
  release.id = 7;
  m.send(release);
  m.run_until_idle();
  s = m.status();
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::none);
  EXPECT_EQ(s.commanded[0], 10);
}

TEST(MachineIo, AbortDuringAHoldStopsCleanly) {
  Rig rig(mill_with_spindle(0));
  auto& m = rig.m;
  m.queue(action(spindle(1, 1000)));
  IoAction hold = of_kind(IoAction::Kind::hold);
  hold.hold = IoAction::Hold::tool_change;
  hold.hold_id = 1;
  m.queue(action(hold));
  m.queue(line_to(Move::Kind::traverse, 10, 0, 0, 0));
  m.flush();
  m.cycles(100);
  EXPECT_TRUE(m.status().spindle.enabled);
  m.command(Command::Kind::abort);
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.wait.kind, WaitStatus::Kind::none);
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_EQ(s.commanded[0], 0);
  EXPECT_EQ(s.machine, MachineState::on);
}

TEST(MachineIo, WaitForAnInputHighOrTimeOut) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  IoAction wait = of_kind(IoAction::Kind::wait_input);
  wait.index = 0;
  wait.mode = 3;  // high
  wait.timeout_s = 2;
  m.queue(action(wait));
  m.flush();
  m.cycles(500);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::input);
  rig.drive.inputs_ = 1u;
  m.run_until_idle();
  EXPECT_EQ(m.status().input_waits, 1u);
  EXPECT_EQ(m.status().input_result, 1);
  // Low again, and nothing comes: -1 after Q seconds.
  rig.drive.inputs_ = 0u;
  m.queue(action(wait));
  const int cycles = m.run_until_idle();
  EXPECT_NEAR(cycles, 2000, 5);
  EXPECT_EQ(m.status().input_waits, 2u);
  EXPECT_EQ(m.status().input_result, -1);
}

TEST(MachineIo, TheOperatorEndsOnlyTheWaitUnderWay) {
  Rig rig(mill_with_spindle(100, 600));
  auto& m = rig.m;
  IoAction wait = of_kind(IoAction::Kind::wait_input);
  wait.index = 2;
  wait.mode = 3;
  wait.timeout_s = 100;
  m.queue(action(wait));
  m.flush();
  m.cycles(50);
  const WaitStatus waiting = m.status().wait;
  ASSERT_EQ(waiting.kind, WaitStatus::Kind::input);
  Command end;
  end.kind = Command::Kind::end_wait;
  end.id = static_cast<std::uint32_t>(WaitStatus::Kind::input);
  end.since = waiting.since - 1;  // an answer to an earlier wait
  m.send(end);
  m.cycles(50);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::input);
  end.since = waiting.since;
  m.send(end);
  m.run_until_idle();
  EXPECT_EQ(m.status().input_waits, 1u);
  EXPECT_EQ(m.status().input_result, -1) << "as on its timeout";

  // At 100 rpm/s the spindle takes 30 s to 3000 rpm: ended while it stands, the wait goes on;
  // ended while it turns, the path goes on below speed.
  m.queue(action(spindle(1, 3000)));
  m.queue(action(of_kind(IoAction::Kind::wait_at_speed)));
  m.flush();
  m.cycles(3);
  const WaitStatus at_speed = m.status().wait;
  ASSERT_EQ(at_speed.kind, WaitStatus::Kind::spindle_at_speed);
  end.id = static_cast<std::uint32_t>(WaitStatus::Kind::spindle_at_speed);
  end.since = at_speed.since;
  m.send(end);
  m.cycles(50);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::spindle_at_speed) << "not turning yet";
  m.cycles(1000);
  m.send(end);
  m.run_until_idle();
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::none);
  EXPECT_LT(rig.drive.rpm(), 500);
}

TEST(MachineIo, WaitForARisingEdgeAndReadAnAnalogInput) {
  Rig rig(mill_with_spindle());
  auto& m = rig.m;
  rig.drive.inputs_ = 1u << 4;  // already high: a rising edge is still to come
  IoAction wait = of_kind(IoAction::Kind::wait_input);
  wait.index = 4;
  wait.mode = 1;
  wait.timeout_s = 10;
  m.queue(action(wait));
  m.flush();
  m.cycles(100);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::input);
  rig.drive.inputs_ = 0;
  m.cycles(10);
  EXPECT_EQ(m.status().wait.kind, WaitStatus::Kind::input);
  rig.drive.inputs_ = 1u << 4;
  m.run_until_idle();
  EXPECT_EQ(m.status().input_result, 1);
  rig.drive.analog_ = 2.75;
  IoAction read = of_kind(IoAction::Kind::wait_input);
  read.digital = false;
  read.index = 0;
  m.queue(action(read));
  m.run_until_idle();
  EXPECT_EQ(m.status().input_result, 2.75);
}

TEST(MachineIo, EstopTurnsEverythingOffAtOnce) {
  Rig rig(mill_with_spindle(0));
  auto& m = rig.m;
  m.queue(action(spindle(1, 1000)));
  IoAction coolant = of_kind(IoAction::Kind::coolant);
  coolant.flood = coolant.mist = true;
  m.queue(action(coolant));
  IoAction out = of_kind(IoAction::Kind::digital_output);
  out.index = 2;
  out.on = true;
  m.queue(action(out));
  IoAction value = of_kind(IoAction::Kind::analog_output);
  value.index = 1;
  value.value = 3;
  m.queue(action(value));
  m.run_until_idle();
  auto s = m.status();
  ASSERT_TRUE(s.spindle.enabled);
  ASSERT_TRUE(s.io.flood && s.io.mist);
  ASSERT_EQ(s.io.douts, 1u << 2);
  m.command(Command::Kind::estop);
  s = m.status();
  EXPECT_FALSE(s.spindle.enabled);
  EXPECT_FALSE(s.io.flood || s.io.mist);
  EXPECT_EQ(s.io.douts, 0u);
  EXPECT_EQ(s.io.aouts[1], 0);
  const auto& last = rig.m.io_trajectory().back();
  EXPECT_FALSE(last.spindle.enable);
  EXPECT_FALSE(last.flood);
  EXPECT_EQ(last.digital, 0u);
}

}  // namespace
}  // namespace cncd::test
