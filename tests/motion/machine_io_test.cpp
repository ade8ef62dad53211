// The spindle, coolant, outputs and waits the servo loop carries out with the path, in virtual
// time: at-speed before feed moves, outputs with the start of a move, holds, M66 waits, and
// everything off on estop, abort and faults.
#include <atomic>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "cncd/drivers/fault_reason.hpp"
#include "cncd/motion/machine_io.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::IoAction;
using motion::MachineState;
using motion::MotionState;
using motion::Move;
using motion::WaitStatus;

// A spindle drive that ramps at the config's ACCELERATION and inputs a test sets: what a
// driver reports, with nothing behind it.
class SpindleDrive final : public FakeDriver {
 public:
  explicit SpindleDrive(double acceleration) : FakeDriver("spindle"), acceleration_(acceleration) {}
  void write_io(const drivers::IoCommand& command) noexcept override { command_ = command; }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    const double want = command_.spindle.enable ? command_.spindle.rpm : 0.0;
    const double step = acceleration_ * 0.001;
    if (acceleration_ <= 0 || std::abs(want - rpm_) <= step) {
      rpm_ = want;
    } else {
      rpm_ += want > rpm_ ? step : -step;
    }
    feedback.spindle.present = true;
    feedback.spindle.rpm = rpm_;
    feedback.spindle.acknowledged = command_.spindle.sequence;
    feedback.spindle.fault = fault_.load();
    feedback.digital = inputs_.load();
    feedback.analog[0] = analog_.load();
  }
  bool fault_reason(char* out, std::size_t size) const noexcept override {
    if (!fault_.load()) return FakeDriver::fault_reason(out, size);
    drivers::copy_text(out, size, "VFD reports overcurrent");
    return true;
  }
  std::atomic<bool> fault_{false};
  std::atomic<std::uint32_t> inputs_{0};
  std::atomic<double> analog_{0};
  double rpm() const { return rpm_; }

 private:
  double acceleration_;
  drivers::IoCommand command_{};
  double rpm_ = 0;
};

config::MachineConfig mill_with_spindle(double acceleration = 3000, double timeout_s = 10) {
  config::MachineConfig c = small_mill();
  c.spindle.present = true;
  // Driven by the test's SpindleDrive (the simulated driver simulates only a sim spindle).
  c.spindle.driver = config::SpindleDriver::modbus;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.min_forward_velocity = 100;
  c.spindle.max_reverse_velocity = 12000;
  c.spindle.min_reverse_velocity = 100;
  c.spindle.acceleration = acceleration;
  c.spindle.at_speed_timeout_s = timeout_s;
  return c;
}

Move action(IoAction a) {
  Move m;
  m.kind = Move::Kind::action;
  m.action = a;
  return m;
}

IoAction spindle(int direction, double rpm) {
  IoAction a;
  a.kind = IoAction::Kind::spindle;
  a.direction = static_cast<std::int8_t>(direction);
  a.rpm = rpm;
  return a;
}

IoAction of_kind(IoAction::Kind kind) {
  IoAction a;
  a.kind = kind;
  return a;
}

struct Rig {
  explicit Rig(const config::MachineConfig& config)
      : config_(config), drive(config.spindle.acceleration), m(config_, kCaps, nullptr, &drive) {
    m.ready();
  }
  static constexpr std::uint32_t kCaps =
      drivers::kCapHomeSwitch | drivers::kCapLimitSwitches | drivers::kCapEstopInput;
  config::MachineConfig config_;
  SpindleDrive drive;
  VirtualMachine m;
};

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
