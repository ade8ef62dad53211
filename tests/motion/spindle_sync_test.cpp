// Motion in step with the spindle, in the servo loop in virtual time: rigid taps (G33.1) and
// threads (G33) on the simulated spindle with its ACCELERATION ramp, the ideal spindle, the
// feed override, a feed hold, an abort, and spindles that stall or run on.
//
// The helix error of a period is the axis's command of that period against the spindle's
// position one period later, when the axis has got there: the sim spindle integrates its speed
// on its own, so the error is measured, not assumed.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/drivers/spindle_position.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::IoAction;
using motion::MotionState;
using motion::Move;
using motion::SpindleSync;
using motion::SyncStatus;

constexpr double kPitch = 1.25;

config::MachineConfig mill_with_sim_spindle(double acceleration = 3000) {
  config::MachineConfig c = small_mill();
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::sim;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.max_reverse_velocity = 24000;
  c.spindle.acceleration = acceleration;
  c.spindle.at_speed_timeout_s = 2;
  return c;
}

Move action(IoAction a) {
  Move m;
  m.kind = Move::Kind::action;
  m.action = a;
  return m;
}

Move spindle_on(double rpm, int direction = 1) {
  IoAction a;
  a.kind = IoAction::Kind::spindle;
  a.direction = static_cast<std::int8_t>(direction);
  a.rpm = rpm;
  return action(a);
}

Move at_speed() {
  IoAction a;
  a.kind = IoAction::Kind::wait_at_speed;
  return action(a);
}

Move synced(SpindleSync kind, double z, double per_rev = kPitch, double rpm = 600) {
  Move m = line_to(Move::Kind::feed, 0, 0, z, per_rev * rpm / 60.0);
  m.spindle_sync = kind;
  m.per_rev = per_rev;
  m.path_mode = Move::PathMode::exact_stop;
  return m;
}

// One period as the axis and the spindle stood.
struct Sample {
  double z = 0;            // commanded at the end of the period
  double revolutions = 0;  // the spindle as read at the start of the period
  double rpm = 0;
  int direction = 0;
  SyncStatus::Phase phase = SyncStatus::Phase::none;
  MotionState motion = MotionState::idle;
};

class SpindleSyncTest : public ::testing::Test {
 protected:
  void start(const config::MachineConfig& config, double rpm = 600, int direction = 1) {
    machine_ = std::make_unique<VirtualMachine>(config);
    machine_->ready();
    machine_->queue(spindle_on(rpm, direction));
    machine_->queue(at_speed());
    machine_->run_until_idle();
    ASSERT_TRUE(machine_->status().spindle.at_speed);
  }
  // Sends `command`, sampling the period that takes it.
  void send(const Command& command) {
    ASSERT_TRUE(machine_->loop().commands().push(command));
    run(1);
  }
  // Runs `n` periods (or until idle with `until_idle`), keeping a sample of each.
  void run(int n, bool until_idle = false) {
    machine_->flush();
    for (int i = 0; i < n; ++i) {
      machine_->cycles(1);
      const motion::Status s = machine_->status();
      samples_.push_back({s.commanded[2], s.spindle.revolutions, s.spindle.actual_rpm,
                          s.spindle.direction, s.sync.phase, s.motion});
      if (until_idle && s.motion == MotionState::idle && s.queued == 0) return;
    }
  }
  // The largest |z - z_ideal| over the samples where the tap held the axis to the spindle:
  // z_ideal = z0 - pitch * direction * (revolutions - locked), with the spindle's position one
  // period later. `locked`: its position when the tap locked to it (at rest).
  double helix_error(double z0, double pitch, int direction, std::size_t from,
                     std::size_t to) const {
    double worst = 0;
    const double locked = samples_[from].revolutions;
    for (std::size_t k = from; k + 1 < samples_.size() && k < to; ++k) {
      const double ideal = z0 - pitch * direction * (samples_[k + 1].revolutions - locked);
      worst = std::max(worst, std::abs(samples_[k].z - ideal));
    }
    return worst;
  }
  // First sample from `from` in `phase`, or samples_.size().
  std::size_t first(SyncStatus::Phase phase, std::size_t from = 0) const {
    for (std::size_t k = from; k < samples_.size(); ++k)
      if (samples_[k].phase == phase) return k;
    return samples_.size();
  }
  std::size_t first_not(SyncStatus::Phase phase, std::size_t from) const {
    for (std::size_t k = from; k < samples_.size(); ++k)
      if (samples_[k].phase != phase) return k;
    return samples_.size();
  }

  std::unique_ptr<VirtualMachine> machine_;
  std::vector<Sample> samples_;
};

TEST_F(SpindleSyncTest, RigidTapStaysOnTheHelixThroughTheReversalAndReturns) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  run(20000, true);
  ASSERT_EQ(machine_->status().motion, MotionState::idle);
  EXPECT_EQ(machine_->status().path_errors, 0u);
  // The spindle came to rest, then the tap locked to it.
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  ASSERT_LT(in, samples_.size());
  EXPECT_GT(in, 0u);
  EXPECT_EQ(samples_[in - 1].phase, SyncStatus::Phase::spindle_stopping);
  EXPECT_LT(samples_[in].rpm, 1.0);
  const std::size_t out = first(SyncStatus::Phase::tapping_out, in);
  const std::size_t end = first(SyncStatus::Phase::none, out);
  ASSERT_LT(end, samples_.size());
  // The whole tap on the helix, well within pitch x 0.02.
  const double error = helix_error(0, kPitch, 1, in, end);
  EXPECT_LE(error, kPitch * 0.02);
  EXPECT_LE(error, 0.002) << "the helix error is meant to be far below the limit";
  // Down to the bottom, and back where it started.
  double deepest = 0;
  for (const Sample& s : samples_)
    deepest = std::min(deepest, s.z);
  EXPECT_NEAR(deepest, -10, 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  // The spindle reversed at the bottom (its position ran back), at full speed both ways.
  double max_rev = -1e300;
  std::size_t bottom = 0;
  for (std::size_t k = in; k < end; ++k) {
    if (samples_[k].revolutions > max_rev) {
      max_rev = samples_[k].revolutions;
      bottom = k;
    }
  }
  EXPECT_NEAR(max_rev - samples_[in].revolutions, 10 / kPitch, 0.01);
  EXPECT_NEAR(samples_[end].revolutions, samples_[in].revolutions, 0.002);
  double fastest_in = 0, fastest_out = 0;
  for (std::size_t k = in; k < end; ++k)
    (k < bottom ? fastest_in : fastest_out) =
        std::max(k < bottom ? fastest_in : fastest_out, samples_[k].rpm);
  EXPECT_NEAR(fastest_in, 600, 1);
  EXPECT_NEAR(fastest_out, 600, 1);
  // Within the axes' limits, and the spindle turns forward again at 600 rpm.
  expect_within_limits(*machine_, {0, 0, 0});
  EXPECT_EQ(machine_->status().spindle.direction, 1);
  run(1000);
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 600, 1e-6);
  EXPECT_GT(samples_.back().revolutions, samples_[end].revolutions + 1);
  EXPECT_EQ(machine_->status().sync.done, 1u);
}

TEST_F(SpindleSyncTest, LeftHandTapTurnsTheOtherWay) {
  start(mill_with_sim_spindle(3000), 600, -1);
  machine_->queue(synced(SpindleSync::tap, -5));
  run(20000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, -1, in, end), 0.002);
  double lowest = 1e300;
  for (std::size_t k = in; k < end; ++k)
    lowest = std::min(lowest, samples_[k].revolutions);
  EXPECT_NEAR(samples_[in].revolutions - lowest, 5 / kPitch, 0.01);
  EXPECT_EQ(machine_->status().spindle.direction, -1);
}

TEST_F(SpindleSyncTest, TheIdealSpindleTapsAlongItsCommand) {
  config::MachineConfig c = small_mill();  // no [SPINDLE_0]: at any speed at once
  start(c);
  machine_->queue(synced(SpindleSync::tap, -10));
  run(20000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, 1, in, end), 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  // Z's acceleration is the ramp's limit: the tap stays within it.
  expect_within_limits(*machine_, {0, 0, 0});
}

TEST_F(SpindleSyncTest, FeedOverrideScalesSpindleAndAxisTogether) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -40));
  run(700);  // well into the hole at full speed
  const Sample full = samples_.back();
  ASSERT_EQ(full.phase, SyncStatus::Phase::tapping_in);
  ASSERT_NEAR(full.rpm, 600, 1e-6);
  const double z_before = samples_[samples_.size() - 11].z;
  const double full_rate = (z_before - full.z) / (10 * machine_->period_s());
  EXPECT_NEAR(full_rate, 600 / 60.0 * kPitch, 0.01);

  send({Command::Kind::feed_override, 0, 0, 0.5});
  run(300);
  const Sample half = samples_.back();
  ASSERT_EQ(half.phase, SyncStatus::Phase::tapping_in);
  EXPECT_NEAR(half.rpm, 300, 1e-6);
  const double half_rate =
      (samples_[samples_.size() - 11].z - half.z) / (10 * machine_->period_s());
  EXPECT_NEAR(half_rate, full_rate / 2, 0.01);
  run(40000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, 1, in, end), 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
}

TEST_F(SpindleSyncTest, FeedHoldLetsTheTapComeBackOut) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  machine_->queue(line_to(Move::Kind::feed, 5, 0, 0, 10));
  run(400);
  ASSERT_EQ(samples_.back().phase, SyncStatus::Phase::tapping_in);
  send({Command::Kind::pause});
  run(5000);
  // Out of the hole, at rest where the tap started, and held there.
  EXPECT_EQ(machine_->status().motion, MotionState::paused);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  EXPECT_NEAR(machine_->status().commanded[0], 0, 1e-12);
  double deepest = 0;
  for (const Sample& s : samples_)
    deepest = std::min(deepest, s.z);
  EXPECT_NEAR(deepest, -10, 0.002);
  const std::size_t end = first(SyncStatus::Phase::none, first(SyncStatus::Phase::tapping_in));
  ASSERT_LT(end, samples_.size());
  for (std::size_t k = 0; k < end; ++k)
    ASSERT_NE(samples_[k].motion, MotionState::paused) << "paused in the hole at " << k;
  EXPECT_EQ(samples_[end].motion, MotionState::paused);
  send({Command::Kind::resume});
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[0], 5, 1e-9);
}

TEST_F(SpindleSyncTest, AbortStopsSpindleAndAxisTogetherInTheHole) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  run(400);
  ASSERT_EQ(samples_.back().phase, SyncStatus::Phase::tapping_in);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t aborted = samples_.size();
  send({Command::Kind::abort});
  run(3000, true);
  EXPECT_EQ(machine_->status().motion, MotionState::idle);
  EXPECT_EQ(machine_->status().spindle.direction, 0);
  EXPECT_LT(machine_->status().spindle.actual_rpm, 1e-9);
  // It stopped in the hole, still on the helix, and within the axes' limits.
  const double z = machine_->status().commanded[2];
  EXPECT_LT(z, samples_[aborted - 1].z);
  EXPECT_GT(z, -10);
  EXPECT_LE(helix_error(0, kPitch, 1, in, samples_.size() - 1), 0.002);
  expect_within_limits(*machine_, {0, 0, 0});
}

TEST_F(SpindleSyncTest, ThreadStartsAtTheIndexAndFollowsTheHelix) {
  start(mill_with_sim_spindle(3000));
  const double at_start = machine_->status().spindle.revolutions;
  machine_->queue(synced(SpindleSync::thread, -30, 1.5));
  run(20000, true);
  EXPECT_EQ(machine_->status().path_errors, 0u);
  EXPECT_NEAR(machine_->status().commanded[2], -30, 1e-9);
  // Nothing moves before the next whole revolution.
  const double index = std::ceil(at_start);
  for (const Sample& s : samples_) {
    if (s.revolutions < index - 0.02) {
      EXPECT_EQ(s.z, 0);
    }
  }
  // Once caught up (within a few revolutions), on the helix from the index until the line's
  // end slows it.
  double worst = 0;
  for (std::size_t k = 0; k + 1 < samples_.size(); ++k) {
    const double z_ideal = -1.5 * (samples_[k + 1].revolutions - index);
    if (samples_[k + 1].revolutions < index + 2 || z_ideal < -28) continue;
    worst = std::max(worst, std::abs(samples_[k].z - z_ideal));
  }
  EXPECT_LE(worst, 1.5 * 0.02);
  expect_within_limits(*machine_, {0, 0, 0});
  // The spindle was left alone.
  EXPECT_EQ(machine_->status().spindle.direction, 1);
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 600, 1e-9);
}

// The signed speed a spindle command asks for, rev/s (forward > 0).
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
TEST_F(SpindleSyncTest, FeedPerRevolutionFollowsTheSpindlesActualSpeed) {
  start(mill_with_sim_spindle(3000));
  Move cut = line_to(Move::Kind::feed, 50, 0, 0, 0.1 * 600 / 60.0);
  cut.feed_per_rev = 0.1;  // 1 mm/s at 600 rpm
  machine_->queue(cut);
  run(1000);
  const double x0 = machine_->status().commanded[0];
  run(100);
  EXPECT_NEAR((machine_->status().commanded[0] - x0) / 0.1, 1.0, 1e-6);
  send({Command::Kind::spindle_override, 0, 0, 0.5});
  run(400);  // the spindle ramps down to 300 rpm in 0.1 s
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 300, 1e-6);
  const double x1 = machine_->status().commanded[0];
  run(100);
  EXPECT_NEAR((machine_->status().commanded[0] - x1) / 0.1, 0.5, 1e-6);
}

// G96: the spindle turns at the surface speed over the tool's distance from X0, within D.
TEST_F(SpindleSyncTest, ConstantSurfaceSpeedFollowsX) {
  machine_ = std::make_unique<VirtualMachine>(mill_with_sim_spindle(60000));
  machine_->ready();
  machine_->queue(line_to(Move::Kind::traverse, 50, 0, 0));
  IoAction css;
  css.kind = IoAction::Kind::spindle;
  css.direction = 1;
  css.rpm = 100;                                            // m/min
  css.css_numerator = 100 * 1000 / (2 * 3.14159265358979);  // mm/min over 2 pi
  css.css_max_rpm = 2000;
  css.css_x_origin = 0;
  machine_->queue(action(css));
  machine_->queue(line_to(Move::Kind::feed, 1, 0, 0, 5));
  for (int i = 0; i < 5000 && machine_->status().spindle.direction == 0; ++i)
    run(1);
  ASSERT_EQ(machine_->status().commanded[0], 50);
  // At X50: 100 m/min / (2 pi 50 mm) = 318.3 rpm.
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 318.31, 0.01);
  // Half way in, twice as fast.
  for (int i = 0; i < 20000 && machine_->status().commanded[0] > 25; ++i)
    run(1);
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 100e3 / (2 * 3.14159265358979 * 25), 0.2);
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[0], 1, 1e-9);
  // At X1 it would be 15,915 rpm: D caps it.
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 2000, 1e-9);
}

}  // namespace
}  // namespace cncd::test
