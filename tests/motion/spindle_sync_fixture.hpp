// The servo loop in virtual time with a spindle, one sample a period: what the spindle-synchronized
// motion tests (spindle_sync_test.cpp, spindle_sync_drives_test.cpp) drive and measure.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test::spindle_sync {

using motion::Command;
using motion::IoAction;
using motion::MotionState;
using motion::Move;
using motion::SpindleSync;
using motion::SyncStatus;

constexpr double kPitch = 1.25;

inline config::MachineConfig mill_with_sim_spindle(double acceleration = 3000) {
  config::MachineConfig c = small_mill();
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::sim;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.max_reverse_velocity = 24000;
  c.spindle.acceleration = acceleration;
  c.spindle.at_speed_timeout_s = 2;
  return c;
}

inline Move action(IoAction a) {
  Move m;
  m.kind = Move::Kind::action;
  m.action = a;
  return m;
}

inline Move spindle_on(double rpm, int direction = 1) {
  IoAction a;
  a.kind = IoAction::Kind::spindle;
  a.direction = static_cast<std::int8_t>(direction);
  a.rpm = rpm;
  return action(a);
}

inline Move at_speed() {
  IoAction a;
  a.kind = IoAction::Kind::wait_at_speed;
  return action(a);
}

inline Move synced(SpindleSync kind, double z, double per_rev = kPitch, double rpm = 600) {
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

}  // namespace cncd::test::spindle_sync
