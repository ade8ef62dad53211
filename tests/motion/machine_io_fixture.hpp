// The servo loop in virtual time with a spindle drive that ramps at the config's ACCELERATION
// and inputs a test sets: what the machine I/O tests drive.
#pragma once

#include <atomic>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "cncd/drivers/fault_reason.hpp"
#include "cncd/motion/machine_io.hpp"
#include "machine_fixture.hpp"

namespace cncd::test::machine_io {

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

inline config::MachineConfig mill_with_spindle(double acceleration = 3000, double timeout_s = 10) {
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

inline Move action(IoAction a) {
  Move m;
  m.kind = Move::Kind::action;
  m.action = a;
  return m;
}

inline IoAction spindle(int direction, double rpm) {
  IoAction a;
  a.kind = IoAction::Kind::spindle;
  a.direction = static_cast<std::int8_t>(direction);
  a.rpm = rpm;
  return a;
}

inline IoAction of_kind(IoAction::Kind kind) {
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

}  // namespace cncd::test::machine_io
