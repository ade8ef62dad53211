// The servo loop in virtual time: estop, pause/resume, abort, faults, homing, dwell.
#include <cmath>
#include <cstring>
#include <initializer_list>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MachineState;
using motion::MotionState;
using motion::Move;

// Queues feed moves at 100 mm/s through each (X, Y) in turn, at Z 0.
void feed_through(VirtualMachine& m, std::initializer_list<std::pair<double, double>> points) {
  for (const auto& [x, y] : points)
    m.queue(line_to(Move::Kind::feed, x, y, 0, 100));
}

// Queues a feed move at 100 mm/s to (X, Y) at Z 0 and runs `periods` periods of it.
void feed_for(VirtualMachine& m, double x, double y, int periods) {
  m.queue(line_to(Move::Kind::feed, x, y, 0, 100));
  m.cycles(periods);
}

TEST(ServoLoop, StartsInEstopAndOnNeedsReset) {
  VirtualMachine m(small_mill());
  m.cycles(1);
  EXPECT_EQ(m.status().machine, MachineState::estop);
  m.command(Command::Kind::on);
  EXPECT_EQ(m.status().machine, MachineState::estop);
  m.command(Command::Kind::reset_estop);
  EXPECT_EQ(m.status().machine, MachineState::off);
  m.command(Command::Kind::on);
  EXPECT_EQ(m.status().machine, MachineState::on);
}

TEST(ServoLoop, EstopStopsWithinOnePeriodAndFlushes) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_through(m, {{100, 0}, {100, 100}});
  m.cycles(300);
  EXPECT_TRUE(m.drives_enabled());
  m.command(Command::Kind::estop);
  EXPECT_FALSE(m.drives_enabled());
  const auto stopped = m.status();
  EXPECT_EQ(stopped.machine, MachineState::estop);
  EXPECT_EQ(stopped.queued, 0u);
  EXPECT_EQ(stopped.segments_done, 2u);
  m.cycles(100);
  EXPECT_EQ(m.status().commanded[0], stopped.commanded[0]);
  EXPECT_GT(stopped.commanded[0], 0);
  EXPECT_LT(stopped.commanded[0], 100);
}

TEST(ServoLoop, PauseHoldsOnThePathAndResumeFinishes) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_for(m, 100, 50, 400);
  m.command(Command::Kind::pause);
  m.cycles(200);  // 100 mm/s stops in 0.05 s at 2000 mm/s^2 (along the path, less)
  const auto held = m.status();
  EXPECT_EQ(held.motion, MotionState::paused);
  EXPECT_EQ(held.velocity, 0);
  m.cycles(500);
  EXPECT_EQ(m.status().commanded, held.commanded);
  // Still on the programmed line y = x / 2.
  EXPECT_NEAR(held.commanded[1], held.commanded[0] / 2, 1e-9);
  m.command(Command::Kind::resume);
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[0], 100);
  EXPECT_EQ(m.status().commanded[1], 50);
}

TEST(ServoLoop, PauseOnAnArcStaysOnTheCircle) {
  VirtualMachine m(small_mill());
  m.ready();
  Move arc;
  arc.kind = Move::Kind::arc;
  arc.center_first = -50;  // from (0,0) counterclockwise around (-50,0) to (-100,0)
  arc.center_second = 0;
  arc.end = {-100, 0, 0, 0, 0, 0, 0, 0, 0};
  arc.turns = 1;
  arc.feed = 100;
  m.queue(arc);
  m.cycles(700);
  m.command(Command::Kind::pause);
  m.cycles(300);
  EXPECT_EQ(m.status().motion, MotionState::paused);
  m.command(Command::Kind::resume);
  m.run_until_idle();
  for (const auto& p : m.trajectory())
    ASSERT_NEAR(std::hypot(p[0] + 50, p[1]), 50, 1e-9);
  EXPECT_EQ(m.status().commanded[0], -100);
  EXPECT_EQ(m.status().commanded[1], 0);
}

TEST(ServoLoop, AbortStopsUnderControlAndFlushes) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_through(m, {{100, 0}, {0, 0}});
  m.cycles(500);
  m.command(Command::Kind::abort);
  m.run_until_idle(1000);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::on);
  EXPECT_EQ(s.queued, 0u);
  EXPECT_EQ(s.segments_done, 2u);
  EXPECT_GT(s.commanded[0], 40);
  EXPECT_LT(s.commanded[0], 60);
  // The machine takes new moves afterwards.
  m.queue(line_to(Move::Kind::traverse, 0, 0, 0));
  m.run_until_idle();
  EXPECT_EQ(m.status().commanded[0], 0);
}

TEST(ServoLoop, FollowingErrorLatchesAFault) {
  VirtualMachine m(small_mill());
  m.ready();
  m.sim().set_lag(0.05);  // 50 ms lag: at 100 mm/s the error grows to ~5 mm
  m.queue(line_to(Move::Kind::feed, 100, 0, 0, 100));
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_TRUE(s.joint_fault[0]);
  EXPECT_NE(std::strstr(s.fault_reason, "following error"), nullptr) << s.fault_reason;
  // The fault was posted for the non-RT side exactly once.
  motion::Event event;
  int faults = 0;
  while (m.loop().events().pop(event))
    faults += event.level == motion::Event::Level::fault;
  EXPECT_EQ(faults, 1);
  // Drives off: the command follows the (lagging) feedback, and stays after the fault.
  m.sim().set_lag(0);
  m.command(Command::Kind::on);
  EXPECT_EQ(m.status().machine, MachineState::on);
  EXPECT_EQ(m.status().fault_reason[0], '\0');
}

TEST(ServoLoop, DriveFaultAndStaleFeedbackLatch) {
  VirtualMachine m(small_mill());
  m.ready();
  m.sim().set_fault(2, true);
  m.cycles(2);
  EXPECT_EQ(m.status().machine, MachineState::off);
  EXPECT_STREQ(m.status().fault_reason,
               "joint 2: drive fault: fault injected on simulated drive 2");
  m.sim().set_fault(2, false);
  m.command(Command::Kind::on);
  m.sim().set_stale(1, true);
  m.cycles(2);
  EXPECT_NE(std::strstr(m.status().fault_reason, "joint 1: feedback is stale"), nullptr);
}

TEST(ServoLoop, LimitSwitchLatches) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_for(m, 100, 0, 100);
  m.sim().set_limit(0, false, true);
  m.cycles(1);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_EQ(s.queued, 0u);
  EXPECT_NE(std::strstr(s.fault_reason, "joint 0: maximum limit switch tripped"), nullptr)
      << s.fault_reason;
}

TEST(ServoLoop, EstopInputLatches) {
  VirtualMachine m(small_mill());
  m.ready();
  m.sim().set_estop_input(true);
  m.cycles(1);
  EXPECT_EQ(m.status().machine, MachineState::estop);
  m.sim().set_estop_input(false);
  m.command(Command::Kind::reset_estop);
  EXPECT_EQ(m.status().machine, MachineState::off);
}

TEST(ServoLoop, HomesInSequenceToHome) {
  auto config = small_mill();
  config.joints[2].home_sequence = 0;  // Z first
  config.joints[0].home_sequence = 1;
  config.joints[1].home_sequence = 1;
  config.joints[2].home_offset = 10;  // Z's position becomes 10, then it moves to HOME = 5
  config.joints[2].home = 5;
  VirtualMachine m(config);
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  m.command(Command::Kind::home, 0xFFFFFFFFu);
  EXPECT_TRUE(m.status().motion == MotionState::homing);
  EXPECT_FALSE(m.status().homed[0]);
  m.cycles(5);
  EXPECT_FALSE(m.status().homed[0]);  // X waits for Z's sequence
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_TRUE(s.homed[0] && s.homed[1] && s.homed[2]);
  EXPECT_EQ(s.commanded[2], 5);
  EXPECT_EQ(s.joint_commanded[2], 5);
  EXPECT_EQ(s.actual[2], 5);
}

TEST(ServoLoop, SwitchHomingWithoutSwitchIsAFault) {
  auto config = small_mill();
  config.joints[0].home_search_vel = 10;
  config.joints[0].home_latch_vel = 1;
  VirtualMachine m(config, drivers::kCapEstopInput);
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  m.command(Command::Kind::home, 1);
  EXPECT_NE(std::strstr(m.status().fault_reason, "switch homing"), nullptr)
      << m.status().fault_reason;
}

TEST(ServoLoop, AMoveThatDoesNotStartHereIsAFaultNotAJump) {
  VirtualMachine m(small_mill());
  m.ready();
  motion::Planner planner(m.config());
  std::string error;
  const auto segment =
      planner.plan(line_to(Move::Kind::feed, 10, 0, 0, 100), {5, 0, 0}, true, error);
  ASSERT_TRUE(segment.has_value()) << error;
  ASSERT_TRUE(m.loop().segments().push(*segment));
  m.cycles(1);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_STREQ(s.fault_reason, "a queued move does not start where the machine stands");
  EXPECT_EQ(s.commanded[0], 0);
}

// Reports a position that is not a number, as a broken drive might.
class NanDriver final : public FakeDriver {
 public:
  NanDriver() : FakeDriver("nan") {}
  void read(drivers::JointFeedback* feedback, int count) noexcept override {
    for (int i = 0; i < count; ++i)
      feedback[i] = drivers::JointFeedback{};
    if (broken) feedback[1].position = std::nan("");
  }
  bool broken = false;
};

TEST(ServoLoop, FeedbackThatIsNotANumberLatches) {
  const auto config = small_mill();
  NanDriver driver;
  motion::ServoLoop loop(config, {{&driver, {0, 1, 2}}});
  for (auto kind : {Command::Kind::reset_estop, Command::Kind::on}) {
    ASSERT_TRUE(loop.commands().push(Command{kind, 0}));
    loop.cycle(0);
  }
  ASSERT_EQ(loop.status().machine, MachineState::on);
  driver.broken = true;
  loop.cycle(0);
  EXPECT_EQ(loop.status().machine, MachineState::off);
  EXPECT_STREQ(loop.status().fault_reason, "joint 1: feedback position is not a number");
}

// A set-point that is not a number (a segment that reached the ring without the planner's
// checks, or feedback that is not a number while the drives are off) is a fault with its
// reason, and never reaches a driver.
TEST(ServoLoop, ANonFiniteSetPointIsAFaultAndNeverSentToADriver) {
  VirtualMachine m(small_mill());
  m.ready();
  motion::Planner planner(m.config());
  std::string error;
  auto segment = planner.plan(line_to(Move::Kind::feed, 10, 5, 0, 100), {}, true, error);
  ASSERT_TRUE(segment.has_value()) << error;
  segment->end[1] = std::nan("");
  ASSERT_TRUE(m.loop().segments().push(*segment));
  m.clear_trajectory();
  m.cycles(50);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_STREQ(s.fault_reason, "non-finite set-point on joint 1");
  EXPECT_TRUE(s.joint_fault[1]);
  ASSERT_FALSE(m.motor_trajectory().empty());
  for (const auto& joints : m.motor_trajectory()) {
    for (int j = 0; j < 3; ++j)
      EXPECT_TRUE(std::isfinite(joints[static_cast<std::size_t>(j)]));
  }
  for (int j = 0; j < 3; ++j)
    EXPECT_TRUE(std::isfinite(s.commanded[j])) << j;
}

// Keeps what the loop writes, and reports a position that is not a number when `broken`.
class NanRecordingDriver final : public FakeDriver {
 public:
  NanRecordingDriver() : FakeDriver("nan") {}
  void write(const drivers::JointCommand* commands, int count) noexcept override {
    for (int i = 0; i < count; ++i)
      all_finite =
          all_finite && std::isfinite(commands[i].position) && std::isfinite(commands[i].velocity);
  }
  void read(drivers::JointFeedback* feedback, int count) noexcept override {
    for (int i = 0; i < count; ++i)
      feedback[i] = drivers::JointFeedback{};
    if (broken) feedback[1].position = std::nan("");
  }
  bool broken = false;
  bool all_finite = true;
};

TEST(ServoLoop, FeedbackThatIsNotANumberNeverComesBackAsACommand) {
  const auto config = small_mill();
  NanRecordingDriver driver;
  motion::ServoLoop loop(config, {{&driver, {0, 1, 2}}});
  ASSERT_TRUE(loop.commands().push(Command{Command::Kind::reset_estop, 0}));
  loop.cycle(0);
  driver.broken = true;  // drives off: the command follows the feedback
  for (int i = 0; i < 10; ++i)
    loop.cycle(0);
  EXPECT_TRUE(driver.all_finite);
  EXPECT_STREQ(loop.status().fault_reason, "non-finite set-point on joint 1");
}

config::MachineConfig gantry_mill() {
  auto config = small_mill();
  config.coordinates = "XYYZ";
  config.joints.insert(config.joints.begin() + 2, config.joints[1]);
  config.joint_count = 4;
  return config;
}

TEST(ServoLoop, GantryJointsFollowTheirAxis) {
  VirtualMachine m(gantry_mill());
  m.ready();
  m.queue(line_to(Move::Kind::feed, 10, 40, -5, 100));
  m.run_until_idle();
  m.cycles(1);  // feedback trails the command by a period
  const auto s = m.status();
  EXPECT_EQ(s.joint_commanded[0], 10);
  EXPECT_EQ(s.joint_commanded[1], 40);
  EXPECT_EQ(s.joint_commanded[2], 40);
  EXPECT_EQ(s.joint_commanded[3], -5);
  EXPECT_EQ(s.actual[1], 40);
}

TEST(ServoLoop, AGantryJointHomedApartFaultsInsteadOfJumping) {
  auto config = gantry_mill();
  config.joints[2].home = 3;  // the twin homes elsewhere
  VirtualMachine m(config);
  m.ready();
  EXPECT_EQ(m.status().joint_commanded[2], 3);
  feed_for(m, 0, 10, 1);
  EXPECT_EQ(m.status().machine, MachineState::off);
  EXPECT_NE(std::strstr(m.status().fault_reason, "joint 2 stands apart from axis Y"), nullptr)
      << m.status().fault_reason;
  EXPECT_EQ(m.motor_position(2), 3);
}

TEST(ServoLoop, MachineOffStopsAtOnceAndDisables) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_for(m, 100, 0, 200);
  m.command(Command::Kind::off);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_EQ(s.queued, 0u);
  EXPECT_FALSE(m.drives_enabled());
  EXPECT_TRUE(s.homed[0]);  // not VOLATILE_HOME
}

TEST(ServoLoop, DwellTakesItsTime) {
  VirtualMachine m(small_mill());
  m.ready();
  Move dwell;
  dwell.kind = Move::Kind::dwell;
  dwell.dwell_s = 0.25;
  m.queue(dwell);
  EXPECT_EQ(m.run_until_idle(), 250);  // 0.25 s at 1 ms a period
}

TEST(ServoLoop, StatisticsCountOverruns) {
  VirtualMachine m(small_mill());
  m.cycles(10);
  EXPECT_EQ(m.status().rt.overruns, 0u);
  EXPECT_EQ(m.status().rt.cycles, 10u);
}

}  // namespace
}  // namespace cncd::test
