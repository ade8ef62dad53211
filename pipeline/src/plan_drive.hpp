// The drives of the plan simulation: every joint is exactly where it is commanded, and a
// spindle the machine simulates ([SPINDLE_0] DRIVER = sim) turns as the sim driver's does
// (drivers::SpindleModel). No switches, no inputs, no faults: the simulation asks what the
// commanded motion is, not what a machine's drives make of it.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/spindle_model.hpp"

namespace cncd::pipeline {

class PlanDrive final : public drivers::Driver {
 public:
  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override {
    if (joints.size() > position_.size()) return "more joints than a machine may have";
    const config::SpindleConfig& spindle = machine.spindle;
    spindle_ = spindle.present && spindle.driver == config::SpindleDriver::sim;
    if (spindle_ && spindle.acceleration < 0)
      return "[SPINDLE_0] ACCELERATION must not be negative (0 = at once)";
    spindle_model_.reset(spindle.acceleration, static_cast<double>(machine.servo_period_ns) * 1e-9);
    return "";
  }
  void enable() override {}
  void disable() override {}
  CNCD_RT void write(const drivers::JointCommand* commands, int count) noexcept override {
    for (int i = 0; i < count && i < static_cast<int>(position_.size()); ++i)
      position_[static_cast<std::size_t>(i)] = commands[i].position;
  }
  CNCD_RT void read(drivers::JointFeedback* feedback, int count) noexcept override {
    for (int i = 0; i < count && i < static_cast<int>(position_.size()); ++i)
      feedback[i].position = position_[static_cast<std::size_t>(i)];
  }
  CNCD_RT void write_io(const drivers::IoCommand& command) noexcept override {
    spindle_model_.command(command.spindle);
  }
  CNCD_RT void read_io(drivers::IoFeedback& feedback) noexcept override {
    if (!spindle_) return;
    drivers::SpindleFeedback& fb = feedback.spindle;
    fb.present = true;
    fb.has_position = true;
    spindle_model_.step(fb, false);
  }
  std::uint32_t capabilities() const noexcept override {
    return drivers::kCapHomeSwitch | drivers::kCapLimitSwitches | drivers::kCapEstopInput;
  }
  const char* name() const noexcept override { return "plan"; }

 private:
  std::array<double, drivers::kMaxJoints> position_{};
  bool spindle_ = false;
  drivers::SpindleModel spindle_model_;
};

}  // namespace cncd::pipeline
