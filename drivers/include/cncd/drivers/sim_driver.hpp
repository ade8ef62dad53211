// The simulated driver: feedback follows the command, optionally through a first-order lag,
// with faults and stale feedback injectable from another thread for tests.
#pragma once

#include <array>
#include <atomic>

#include "cncd/drivers/driver.hpp"

namespace cncd::drivers {

class SimDriver final : public Driver {
 public:
  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  void enable() override {}
  void disable() override {}
  void write(const JointCommand* commands, int count) noexcept override;
  void read(JointFeedback* feedback, int count) noexcept override;
  void read_inputs(MachineInputs& inputs) noexcept override;
  std::uint32_t capabilities() const noexcept override { return kCapEstopInput; }
  const char* name() const noexcept override { return "sim"; }

  // Any thread. Feedback lags the command with this time constant (0 = echo).
  void set_lag(double time_constant_s) noexcept { lag_s_.store(time_constant_s); }
  // Any thread. Injected faults for the joint at `index` (position in configure()'s list).
  void set_fault(int index, bool fault) noexcept;
  void set_stale(int index, bool stale) noexcept;
  void set_limit(int index, bool min_limit, bool max_limit) noexcept;
  void set_estop_input(bool asserted) noexcept { estop_.store(asserted); }

 private:
  double period_s_ = 0.001;
  std::atomic<double> lag_s_{0};
  std::atomic<bool> estop_{false};
  std::array<std::atomic<bool>, kMaxJoints> fault_{};
  std::array<std::atomic<bool>, kMaxJoints> stale_{};
  std::array<std::atomic<bool>, kMaxJoints> min_limit_{};
  std::array<std::atomic<bool>, kMaxJoints> max_limit_{};
  std::array<double, kMaxJoints> commanded_{};
  std::array<double, kMaxJoints> position_{};
  bool primed_ = false;
};

}  // namespace cncd::drivers
