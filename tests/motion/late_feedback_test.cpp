// The following error against late feedback: a drive whose position comes back some periods
// after the command it answers (as Modbus drives' does) and says which command that was.
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <string>

#include <gtest/gtest.h>

#include "cncd/motion/command_history.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using drivers::JointCommand;
using motion::Command;
using motion::MachineState;
using motion::Move;

// Stands where the command of `delay` periods before the latest put it, reached through a
// first-order lag of `lag_s` seconds (0: at once); commands sent with the drives off do not
// move it. Its feedback names that command's cycle, or 0 when `names_cycle` is false (then
// it claims to answer the latest command, as feedback did before drivers could say).
class LateDriver final : public FakeDriver {
 public:
  LateDriver(int delay, double period_s, double lag_s, bool names_cycle = true)
      : FakeDriver("late", drivers::kCapPositionFeedback),
        delay_(static_cast<std::size_t>(delay)),
        alpha_(lag_s > 0 ? 1.0 - std::exp(-period_s / lag_s) : 1.0),
        names_cycle_(names_cycle) {}
  void write(const JointCommand* commands, int count) noexcept override {
    std::array<JointCommand, drivers::kMaxJoints> block{};
    std::copy_n(commands, std::min(count, drivers::kMaxJoints), block.begin());
    sent_.push_back(block);  // test code: allocation is fine here
    if (sent_.size() > delay_ + 1) sent_.pop_front();
  }
  void read(drivers::JointFeedback* feedback, int count) noexcept override {
    for (int i = 0; i < count && i < drivers::kMaxJoints; ++i) {
      const auto k = static_cast<std::size_t>(i);
      feedback[i] = drivers::JointFeedback{};
      if (sent_.size() == delay_ + 1) {
        const JointCommand& answered = sent_.front()[k];
        if (answered.enable && !jammed_)
          position_[k] += (answered.position - position_[k]) * alpha_;
        feedback[i].command_cycle = names_cycle_ ? answered.cycle : 0;
      }
      feedback[i].position = position_[k];
    }
  }
  // From now on the drive stays where it is, its feedback answering newer commands still.
  void jam() { jammed_ = true; }
  std::int64_t feedback_deadline_ns() const noexcept override {
    return static_cast<std::int64_t>(delay_) * 1'000'000;
  }

 private:
  std::size_t delay_;
  double alpha_;
  bool names_cycle_;
  bool jammed_ = false;
  std::deque<std::array<JointCommand, drivers::kMaxJoints>> sent_;
  std::array<double, drivers::kMaxJoints> position_{};
};

// A drive given the latest command only every `update` periods, as a Modbus bus does, and read
// right after each: it follows its target through a first-order lag of `lag_s`, and its
// feedback, refreshed at each update, names the command just written and, when
// `names_previous`, the one before, which it had the whole update to follow.
class SlowBusDriver final : public FakeDriver {
 public:
  SlowBusDriver(int update, double period_s, double lag_s, bool names_previous)
      : FakeDriver("slow bus", drivers::kCapPositionFeedback),
        update_(update),
        alpha_(lag_s > 0 ? 1.0 - std::exp(-period_s / lag_s) : 1.0),
        names_previous_(names_previous) {}
  void write(const JointCommand* commands, int count) noexcept override {
    std::copy_n(commands, std::min(count, drivers::kMaxJoints), latest_.begin());
  }
  void read(drivers::JointFeedback* feedback, int count) noexcept override {
    const bool exchange = ++periods_ % update_ == 0;
    for (int i = 0; i < count && i < drivers::kMaxJoints; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (target_[k].enable) position_[k] += (target_[k].position - position_[k]) * alpha_;
      if (exchange) {
        previous_[k] = target_[k].cycle;
        target_[k] = latest_[k];
        read_back_[k] = position_[k];
      }
      feedback[i] = drivers::JointFeedback{};
      feedback[i].position = read_back_[k];
      feedback[i].command_cycle = target_[k].cycle;
      feedback[i].previous_cycle = names_previous_ ? previous_[k] : 0;
    }
  }
  std::int64_t feedback_deadline_ns() const noexcept override { return 2LL * update_ * 1'000'000; }

 private:
  int update_;
  double alpha_;
  bool names_previous_;
  int periods_ = 0;
  std::array<JointCommand, drivers::kMaxJoints> latest_{};
  std::array<JointCommand, drivers::kMaxJoints> target_{};
  std::array<std::uint64_t, drivers::kMaxJoints> previous_{};
  std::array<double, drivers::kMaxJoints> position_{};
  std::array<double, drivers::kMaxJoints> read_back_{};
};

constexpr int kDelay = 15;  // periods: 3 mm at X's 200 mm/s, three times its FERROR of 1 mm

struct LateMachine {
  explicit LateMachine(double lag_s, bool names_cycle = true,
                       const config::MachineConfig& config = small_mill())
      : drive(kDelay, 1e-3, lag_s, names_cycle), machine(config, 0, &drive) {
    machine.ready();
  }
  // A traverse along X at its full 200 mm/s for most of the way.
  void fast_move() {
    machine.queue(line_to(Move::Kind::traverse, 300, 0, 0));
    machine.run_until_idle(5000);
    machine.cycles(kDelay + 5);  // the late feedback of the end comes in
  }
  std::string fault() const { return machine.status().fault_reason; }
  LateDriver drive;
  VirtualMachine machine;
};

TEST(LateFeedback, AFastMoveWithTheNormalFerrorDoesNotFault) {
  LateMachine m(0);
  EXPECT_EQ(m.fault(), "");
  m.fast_move();
  EXPECT_EQ(m.fault(), "");
  EXPECT_EQ(m.machine.status().machine, MachineState::on);
  EXPECT_DOUBLE_EQ(m.machine.status().actual[0], 300);
  // The speed came near X's limit, so the latency was worth 3 mm on the way.
  EXPECT_GT(peaks(m.machine, {}).velocity, 0.99);
}

TEST(LateFeedback, TheSameDriveNotSayingWhatItAnswersFaults) {
  // Compared with the latest command, the 15 periods of latency look like 3 mm of error.
  LateMachine m(0, false);
  m.fast_move();
  EXPECT_EQ(m.machine.status().machine, MachineState::off);
  EXPECT_NE(m.fault().find("joint 0: following error"), std::string::npos) << m.fault();
  EXPECT_EQ(m.fault().find("periods ago"), std::string::npos) << m.fault();
}

TEST(LateFeedback, ADriveThatFollowsWithinTheLimitDoesNotFault) {
  // 2 ms behind its commands: 0.4 mm at full speed, under both FERROR and MIN_FERROR.
  LateMachine m(0.002);
  m.fast_move();
  EXPECT_EQ(m.fault(), "");
  EXPECT_NEAR(m.machine.status().actual[0], 300, 1e-3);
}

TEST(LateFeedback, ADriveThatReallyLagsStillFaults) {
  // 10 ms behind its commands on top of the latency: 2 mm at full speed, over FERROR.
  LateMachine m(0.01);
  m.fast_move();
  const auto s = m.machine.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_TRUE(s.joint_fault[0]);
  EXPECT_NE(m.fault().find("joint 0: following error"), std::string::npos) << m.fault();
  EXPECT_NE(m.fault().find("(against the command of 15 periods ago)"), std::string::npos)
      << m.fault();
  EXPECT_LT(s.actual[0], 300);
}

TEST(LateFeedback, ADriveThatStopsMidMoveFaults) {
  LateMachine m(0);
  m.machine.queue(line_to(Move::Kind::traverse, 300, 0, 0));
  m.machine.flush();
  m.machine.cycles(300);
  ASSERT_EQ(m.fault(), "");
  // Jammed: it stays where it is while its feedback keeps answering the newer commands.
  m.drive.jam();
  const double jammed_at = m.machine.status().actual[0];
  m.machine.cycles(20);
  EXPECT_EQ(m.machine.status().machine, MachineState::off);
  EXPECT_NE(m.fault().find("joint 0: following error"), std::string::npos) << m.fault();
  // Caught once the answered command is FERROR (1 mm at full speed) past the jam; the latest
  // command is 15 periods (3 mm) further, and one more period goes to noticing.
  EXPECT_LT(m.machine.status().commanded[0] - jammed_at, 1.0 + 3.0 + 2 * 0.2);
}

TEST(LateFeedback, HomingMovesTheJointsButTheComparisonStaysInMotorUnits) {
  auto config = small_mill();
  for (auto& joint : config.joints)
    joint.home_offset = 5;  // homing calls the motors' 0 joint position 5, then goes to 0
  LateMachine m(0, true, config);
  m.machine.cycles(1);
  EXPECT_EQ(m.fault(), "");
  EXPECT_DOUBLE_EQ(m.machine.status().joint_actual[0], 0);
  EXPECT_DOUBLE_EQ(m.machine.motor_position(0), -5);
  m.fast_move();
  EXPECT_EQ(m.fault(), "");
  EXPECT_DOUBLE_EQ(m.machine.motor_position(0), 295);
}

TEST(LateFeedback, OffAndOnAgainMidMoveDoesNotFault) {
  // Off mid-move: the drive still plays back the commands it had been sent before the drives
  // went off, then stops where they left it; the feedback for the periods the drives were off
  // answers commands nobody had to follow.
  LateMachine m(0);
  m.machine.queue(line_to(Move::Kind::traverse, 300, 0, 0));
  m.machine.flush();
  m.machine.cycles(300);
  m.machine.command(Command::Kind::off);
  m.machine.cycles(3);
  m.machine.command(Command::Kind::on);
  m.machine.cycles(200);
  EXPECT_EQ(m.fault(), "");
  EXPECT_EQ(m.machine.status().machine, MachineState::on);
  m.fast_move();
  EXPECT_EQ(m.fault(), "");
}

// A bus held up for 40 periods between updates: the drive gets targets 8 mm apart at X's
// 200 mm/s and is read back right after each, still standing on the one before.
struct SlowBusMachine {
  SlowBusMachine(double lag_s, bool names_previous)
      : drive(40, 1e-3, lag_s, names_previous), machine(small_mill(), 0, &drive) {
    machine.cycles(80);  // a first update or two, before anything moves
    machine.ready();
    machine.queue(line_to(Move::Kind::traverse, 300, 0, 0));
    machine.run_until_idle(5000);
    machine.cycles(100);
  }
  std::string fault() const { return machine.status().fault_reason; }
  SlowBusDriver drive;
  VirtualMachine machine;
};

TEST(LateFeedback, ADriveUpdatedRarelyIsJudgedBetweenItsLastTwoTargets) {
  SlowBusMachine m(0.002, true);
  EXPECT_EQ(m.fault(), "");
  EXPECT_NEAR(m.machine.status().actual[0], 300, 1e-6);
}

TEST(LateFeedback, AgainstItsNewestTargetAloneTheSameDriveFaults) {
  SlowBusMachine m(0.002, false);
  EXPECT_NE(m.fault().find("joint 0: following error"), std::string::npos) << m.fault();
}

TEST(LateFeedback, ADriveUpdatedRarelyThatLagsItsTargetsFaults) {
  // 20 ms behind its targets: 4 mm at full speed, past the older target by more than FERROR.
  SlowBusMachine m(0.02, true);
  EXPECT_NE(m.fault().find("joint 0: following error"), std::string::npos) << m.fault();
  EXPECT_NE(m.fault().find("(against the commands of"), std::string::npos) << m.fault();
}

JointCommand at(double position, std::uint64_t cycle) {
  return JointCommand{position, position * 10, true, cycle};
}

TEST(CommandHistory, FindsACycleOrTheOldestOrTheLatest) {
  motion::CommandHistory history(2, 4);
  EXPECT_EQ(history.find(0, 1), nullptr);  // nothing recorded
  for (std::uint64_t c = 1; c <= 10; ++c) {
    const JointCommand block[2] = {at(static_cast<double>(c), c), at(-static_cast<double>(c), c)};
    history.record(c, block);
  }
  EXPECT_EQ(history.oldest(), 7u);
  EXPECT_EQ(history.latest(), 10u);
  EXPECT_EQ(history.find(0, 8)->position, 8);
  EXPECT_EQ(history.find(1, 8)->position, -8);
  EXPECT_EQ(history.find(1, 8)->velocity, -80);
  EXPECT_EQ(history.find(0, 3)->position, 7);    // fell out: the oldest held, never newer
  EXPECT_EQ(history.find(0, 0)->position, 10);   // "the latest"
  EXPECT_EQ(history.find(0, 11)->position, 10);  // not written yet: the latest
  EXPECT_EQ(history.find(2, 8), nullptr);        // no such joint
}

TEST(CommandHistory, AGapStartsAfresh) {
  motion::CommandHistory history(1, 8);
  for (std::uint64_t c = 1; c <= 5; ++c) {
    const JointCommand block[1] = {at(static_cast<double>(c), c)};
    history.record(c, block);
  }
  const JointCommand later[1] = {at(20, 20)};
  history.record(20, later);
  history.record(4, later);  // older than the latest: ignored
  EXPECT_EQ(history.oldest(), 20u);
  // Cycle 13's slot (13 % 8 = 5) still holds cycle 5: never taken for it.
  EXPECT_EQ(history.find(0, 13)->position, 20);
  EXPECT_EQ(history.find(0, 13)->cycle, 20u);
}

TEST(CommandHistory, DepthReachesTheDriversDeadline) {
  using motion::CommandHistory;
  EXPECT_EQ(CommandHistory::depth_for(0, 1'000'000), CommandHistory::kMinDepth);
  // modbus_sim.ini: (5 x 2 + 2 x 50) ms stale deadline plus a 2 ms update, at 1 ms periods.
  EXPECT_EQ(CommandHistory::depth_for(112'000'000, 1'000'000), 1024u);
  EXPECT_EQ(CommandHistory::depth_for(1'500'000'000, 1'000'000), 2048u);
  EXPECT_EQ(CommandHistory::depth_for(1'500'000'000, 25'000), 65536u);
  EXPECT_EQ(CommandHistory::depth_for(1'500'000'000, 1'000), CommandHistory::kMaxDepth);
}

}  // namespace
}  // namespace cncd::test
