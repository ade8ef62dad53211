// Spindle-synchronized motion on spindles the test drives itself: one that runs on past the
// bottom of a tap, one whose position jumps, one that does not turn, one on a field bus that
// reports late, and one that turns by the clock through a late servo period.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/drivers/spindle_position.hpp"
#include "spindle_sync_fixture.hpp"

namespace cncd::test {
namespace {

using namespace spindle_sync;

double told_rps(const drivers::IoCommand& command) {
  const auto& sp = command.spindle;
  return !sp.enable ? 0.0 : (sp.reverse ? -sp.rpm : sp.rpm) / 60.0;
}

// A spindle drive with an encoder that turns as it was told `delay` periods ago (at once at
// that speed), or, `dead`, not at all.
class LateSpindle final : public FakeDriver {
 public:
  LateSpindle(std::size_t delay, bool dead) : FakeDriver("late"), delay_(delay), dead_(dead) {}
  void write_io(const drivers::IoCommand& command) noexcept override {
    told_.push_back(told_rps(command));  // test code
    sequences_.push_back(command.spindle.sequence);
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    const bool has = told_.size() > delay_;
    const double rps = dead_ || !has ? 0.0 : told_[told_.size() - 1 - delay_];
    revolutions_ += rps * 0.001;
    feedback.spindle.present = true;
    feedback.spindle.acknowledged = has ? sequences_[told_.size() - 1 - delay_] : 0;
    feedback.spindle.has_position = true;
    feedback.spindle.rpm = std::abs(rps) * 60;
    feedback.spindle.revolutions = revolutions_;
  }

 private:
  std::size_t delay_;
  bool dead_;
  std::vector<double> told_;
  std::vector<std::uint64_t> sequences_;
  double revolutions_ = 0;
};

config::MachineConfig mill_with_driven_spindle() {
  config::MachineConfig c = small_mill();
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::modbus;  // driven by the test's driver
  c.spindle.max_forward_velocity = 24000;
  c.spindle.max_reverse_velocity = 24000;
  c.spindle.at_speed_timeout_s = 0.5;
  return c;
}

TEST_F(SpindleSyncTest, ASpindleThatRunsOnPastTheBottomStopsTheTap) {
  LateSpindle spindle(300, false);  // does as told 0.3 s later
  VirtualMachine m(mill_with_driven_spindle(), drivers::kCapHomeSwitch, nullptr, &spindle);
  m.ready();
  m.queue(spindle_on(600));
  m.queue(synced(SpindleSync::tap, -2));
  m.queue(line_to(Move::Kind::feed, 5, 0, 0, 10));
  m.run_until_idle(20000);
  const motion::Status s = m.status();
  EXPECT_EQ(s.path_errors, 1u);
  EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::sync_overrun);
  EXPECT_NE(motion::format_event(s.path_error).find("past the end of the rigid tap"),
            std::string::npos)
      << motion::format_event(s.path_error);
  // The axis went no further than the bottom, and the program's next move never ran.
  EXPECT_GE(s.commanded[2], -2 - 1e-9);
  EXPECT_EQ(s.commanded[0], 0);
  EXPECT_EQ(s.spindle.direction, 0);
}

// A spindle drive with an encoder that does as told at once, until its reading jumps 3
// revolutions as it passes `jump_at` (3.01 in that period at 600 rpm).
class JumpingSpindle final : public FakeDriver {
 public:
  explicit JumpingSpindle(double jump_at) : FakeDriver("jumping"), jump_at_(jump_at) {}
  void write_io(const drivers::IoCommand& command) noexcept override {
    rps_ = told_rps(command);
    sequence_ = command.spindle.sequence;
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    feedback.spindle.acknowledged = sequence_;
    const double before = revolutions_;
    revolutions_ += rps_ * 0.001;
    if (before < jump_at_ && revolutions_ >= jump_at_) revolutions_ += 3;
    feedback.spindle.present = true;
    feedback.spindle.has_position = true;
    feedback.spindle.rpm = std::abs(rps_) * 60;
    feedback.spindle.revolutions = revolutions_;
  }

 private:
  double jump_at_;
  std::uint64_t sequence_ = 0;
  double rps_ = 0;
  double revolutions_ = 0;
};

TEST_F(SpindleSyncTest, APositionThatJumpsStopsTheTapWhereItWas) {
  JumpingSpindle spindle(5);
  VirtualMachine m(mill_with_driven_spindle(), drivers::kCapHomeSwitch, nullptr, &spindle);
  m.ready();
  m.queue(spindle_on(600));
  m.queue(synced(SpindleSync::tap, -20));
  m.run_until_idle(20000);
  const motion::Status s = m.status();
  EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::sync_jump);
  EXPECT_NE(motion::format_event(s.path_error).find("jumped 3.01 revolutions in one servo period"),
            std::string::npos)
      << motion::format_event(s.path_error);
  // The axis never took the jump: never faster than its limit, and it stopped in the hole (at
  // once: the spindle's position can no longer be followed).
  EXPECT_LE(peaks(m, {0, 0, 0}).velocity, 1.001);
  EXPECT_LT(s.commanded[2], -1);
  EXPECT_GT(s.commanded[2], -20);
  EXPECT_EQ(s.spindle.direction, 0);
}

TEST_F(SpindleSyncTest, ASpindleThatDoesNotTurnEndsTheMove) {
  LateSpindle spindle(0, true);
  VirtualMachine m(mill_with_driven_spindle(), drivers::kCapHomeSwitch, nullptr, &spindle);
  m.ready();
  m.queue(spindle_on(600));
  m.queue(synced(SpindleSync::tap, -2));
  const int cycles = m.run_until_idle(20000);
  const motion::Status s = m.status();
  EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::sync_stalled);
  EXPECT_NE(motion::format_event(s.path_error).find("did not turn for 0.5 s"), std::string::npos)
      << motion::format_event(s.path_error);
  EXPECT_LT(cycles, 2000);
  EXPECT_EQ(s.commanded[2], 0);
}

// A servo spindle on a field bus, in virtual time: every `update_ms` the bus hands the drive
// the latest command and reads the drive's position counter (4096 counts a revolution, 16
// bits), the request arriving `latency_ms` later and the answer as much again. The shaft ramps
// at `acceleration` rpm/s toward the speed last handed over. The position the servo loop gets
// is the driver's: SpindlePositionTracker's prediction from the readings.
class BusSpindle final : public FakeDriver {
 public:
  BusSpindle(int update_ms, int latency_ms, double acceleration)
      : FakeDriver("bus"), update_ms_(update_ms), latency_ms_(latency_ms), accel_(acceleration) {
    tracker_.configure(16, kCounts, acceleration / 60.0, 200 * kMs);
  }
  void write_io(const drivers::IoCommand& command) noexcept override {
    told_rpm_ = told_rps(command) * 60.0;
    told_sequence_ = command.spindle.sequence;
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    // This period's moment, in 0.1 ms steps of the shaft.
    for (int i = 0; i < 10; ++i) {
      const std::int64_t t = now_ + i * kMs / 10;
      const std::int64_t into = t % (update_ms_ * kMs);
      if (into == 0) {
        // the bus takes the command...
        request_rpm_ = told_rpm_;
        request_sequence_ = told_sequence_;
      }
      if (into == latency_ms_ * kMs) {
        // ... it reaches the drive, which reads its counter as it takes it
        target_rpm_ = request_rpm_;
        acknowledged_ = request_sequence_;
        sampled_ = Reading{counts(), t};
      }
      if (into == 2 * latency_ms_ * kMs) tracker_.add(sampled_.raw, sampled_.time_ns);
      const double before = rpm_;
      rpm_ = rpm_ < target_rpm_ ? std::min(target_rpm_, rpm_ + accel_ * 1e-4)
                                : std::max(target_rpm_, rpm_ - accel_ * 1e-4);
      revolutions_ += 0.5 * (before + rpm_) / 60.0 * 1e-4;
    }
    now_ += kMs;
    truth_ = revolutions_;
    feedback.spindle.present = true;
    feedback.spindle.rpm = std::abs(rpm_);
    feedback.spindle.acknowledged = acknowledged_;
    feedback.spindle.has_position = tracker_.fit().valid;
    feedback.spindle.revolutions = tracker_.fit().at(now_, 200 * kMs);
    feedback.spindle.time_ns = now_;
    // A command waits half an update on average, then goes its way.
    feedback.spindle.command_delay_ns = update_ms_ * kMs / 2 + latency_ms_ * kMs;
  }
  // The shaft's true position at the moment of the last read_io.
  double truth() const { return truth_; }

 private:
  static constexpr std::int64_t kMs = 1'000'000;
  static constexpr double kCounts = 4096;
  struct Reading {
    std::uint32_t raw = 0;
    std::int64_t time_ns = 0;
  };
  std::uint32_t counts() const {
    return static_cast<std::uint32_t>(
        static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(revolutions_ * kCounts))) &
        0xFFFFu);
  }
  int update_ms_;
  int latency_ms_;
  double accel_;
  drivers::SpindlePositionTracker tracker_;
  std::int64_t now_ = 0;
  double told_rpm_ = 0;
  double request_rpm_ = 0;
  std::uint64_t told_sequence_ = 0;
  std::uint64_t request_sequence_ = 0;
  std::uint64_t acknowledged_ = 0;
  double target_rpm_ = 0;
  double rpm_ = 0;
  double revolutions_ = 0;
  double truth_ = 0;
  Reading sampled_;
};

TEST_F(SpindleSyncTest, RigidTapStaysOnTheHelixOfASpindleOnAFieldBus) {
  // A Modbus servo spindle read every 10 ms with 1 ms each way: the last reading is up to
  // 12 ms (0.12 revolutions at 600 rpm, 0.15 mm of a 1.25 pitch) old, and the drive takes a
  // new speed as late. The tap stays on the helix of the shaft's true position.
  BusSpindle spindle(10, 1, 3000);
  config::MachineConfig c = mill_with_driven_spindle();
  c.spindle.acceleration = 3000;
  VirtualMachine m(c, drivers::kCapHomeSwitch, nullptr, &spindle);
  m.ready();
  m.queue(spindle_on(600));
  m.queue(at_speed());
  m.queue(synced(SpindleSync::tap, -10));
  m.flush();
  struct Period {
    double z;
    double truth;
    SyncStatus::Phase phase;
  };
  std::vector<Period> periods;
  for (int i = 0; i < 20000; ++i) {
    m.cycles(1);
    const motion::Status s = m.status();
    periods.push_back({s.commanded[2], spindle.truth(), s.sync.phase});
    if (s.motion == MotionState::idle && s.queued == 0) break;
  }
  const motion::Status s = m.status();
  ASSERT_EQ(s.motion, MotionState::idle);
  EXPECT_EQ(s.path_errors, 0u) << motion::format_event(s.path_error);
  std::size_t in = 0;
  while (in < periods.size() && periods[in].phase != SyncStatus::Phase::tapping_in)
    ++in;
  ASSERT_LT(in, periods.size());
  // Each period's axis command against where the shaft truly is when the period ends.
  const double locked = periods[in].truth;
  double worst = 0;
  double deepest = 0;
  for (std::size_t k = in; k + 1 < periods.size(); ++k) {
    if (periods[k].phase == SyncStatus::Phase::none) break;
    const double ideal = -kPitch * (periods[k + 1].truth - locked);
    worst = std::max(worst, std::abs(periods[k].z - ideal));
    deepest = std::min(deepest, periods[k].z);
  }
  // The tap allows for the commands on their way (SpindleFeedback::command_delay_ns): the
  // spindle comes to rest at the bottom (8 revolutions) and back at the top within a few
  // thousandths of a revolution, where taking the position alone left it 0.011 on.
  double most = 0;
  double least = 0;
  for (std::size_t k = in; k < periods.size(); ++k) {
    most = std::max(most, periods[k].truth - locked);
    least = std::min(least, periods[k].truth - locked);
  }
  std::printf("bus spindle: largest helix error %.5f mm; past the bottom %.5f, the top %.5f rev\n",
              worst, most - 8, -least);
  EXPECT_LE(worst, kPitch * 0.02);
  EXPECT_LE(most - 8, 0.005);
  EXPECT_LE(-least, 0.005);
  EXPECT_NEAR(deepest, -10, 0.01);
  EXPECT_NEAR(s.commanded[2], 0, 1e-9);
  EXPECT_EQ(s.spindle.direction, 1);
}

// A spindle that turns by the clock, with a servo loop that runs late now and then: every
// 200th period starts 6 ms late and the next five catch up at once, as a servo thread does
// after a stall. The driver says when the spindle stood where (SpindleFeedback::time_ns).
class ClockSpindle final : public FakeDriver {
 public:
  explicit ClockSpindle(bool stamped) : FakeDriver("clock"), stamped_(stamped) {}
  void write_io(const drivers::IoCommand& command) noexcept override {
    rps_ = told_rps(command);
    sequence_ = command.spindle.sequence;
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    feedback.spindle.acknowledged = sequence_;
    ++period_;
    const std::int64_t step = period_ % 200 == 0 ? 6'000'000 : period_ % 200 <= 5 ? 0 : 1'000'000;
    now_ += step;
    revolutions_ += rps_ * static_cast<double>(step) * 1e-9;
    feedback.spindle.present = true;
    feedback.spindle.has_position = true;
    feedback.spindle.rpm = std::abs(rps_) * 60;
    feedback.spindle.revolutions = revolutions_;
    feedback.spindle.time_ns = stamped_ ? now_ : 0;
  }

 private:
  bool stamped_;
  std::uint64_t sequence_ = 0;
  std::int64_t period_ = 0;
  std::int64_t now_ = 1'000'000'000;
  double rps_ = 0;
  double revolutions_ = 0;
};

TEST_F(SpindleSyncTest, ALateServoPeriodIsNoJumpOfASpindleThatTurnsByTheClock) {
  for (const bool stamped : {true, false}) {
    SCOPED_TRACE(stamped ? "stamped" : "not stamped");
    ClockSpindle spindle(stamped);
    VirtualMachine m(mill_with_driven_spindle(), drivers::kCapHomeSwitch, nullptr, &spindle);
    m.ready();
    m.queue(spindle_on(600));
    m.queue(synced(SpindleSync::tap, -10));
    m.run_until_idle(40000);
    const motion::Status s = m.status();
    if (stamped) {
      // 0.06 revolutions in a period 6 ms long is the spindle's own speed.
      EXPECT_EQ(s.path_errors, 0u) << motion::format_event(s.path_error);
      EXPECT_NEAR(s.commanded[2], 0, 1e-9);
    } else {
      // Without the time, the same step is a position that jumped: the tap stops.
      EXPECT_EQ(s.path_error.code, motion::RtEvent::Code::sync_jump);
    }
  }
}

// G95: the feed follows the spindle as it turns, not as programmed: a spindle override of
// 50 % halves it.
}  // namespace
}  // namespace cncd::test
