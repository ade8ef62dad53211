// The simulated driver: feedback follows the command, optionally through a first-order lag,
// with home switches simulated at set positions and faults, stale feedback, limit switches
// and the estop input injectable from any thread (tests, demos).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

class SimDriver final : public Driver {
 public:
  // Non-RT. Every joint with a HOME_SEARCH_VEL gets a home switch at motor position
  // HOME_OFFSET (as if the machine powered up with motor and joint positions equal), closed
  // from there on in the search direction, like a cam that a search runs onto. Each joint's
  // `[JOINT_n] SIM_LAG` (seconds) sets its lag.
  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  void enable() override {}
  void disable() override {}
  // RT: positions are in motor units; the first write also sets the simulated position.
  CNCD_RT void write(const JointCommand* commands, int count) noexcept override;
  // RT.
  CNCD_RT void read(JointFeedback* feedback, int count) noexcept override;
  CNCD_RT void read_inputs(MachineInputs& inputs) noexcept override;
  // RT-safe, any thread: names the first joint with an injected fault.
  CNCD_RT bool fault_reason(char* out, std::size_t size) const noexcept override;
  std::uint32_t capabilities() const noexcept override {
    return kCapHomeSwitch | kCapLimitSwitches | kCapEstopInput;
  }
  const char* name() const noexcept override { return "sim"; }

  // The injection API below is for any thread; `index` is the joint's position in
  // configure()'s list, out-of-range indexes are ignored.

  // Feedback of every joint lags the command with this time constant in seconds (0 = exact
  // echo).
  void set_lag(double time_constant_s) noexcept;
  void set_fault(int index, bool fault) noexcept;
  void set_stale(int index, bool stale) noexcept;
  void set_limit(int index, bool min_limit, bool max_limit) noexcept;
  void set_estop_input(bool asserted) noexcept { estop_.store(asserted); }
  // Home switch closed at motor positions >= `position` (direction > 0) or <= `position`
  // (direction < 0); direction 0 removes the switch.
  void set_home_switch(int index, double position, int direction) noexcept;

 private:
  struct HomeSwitch {
    std::atomic<double> position{0};
    std::atomic<int> direction{0};
  };
  static bool valid(int index) noexcept { return index >= 0 && index < kMaxJoints; }

  double period_s_ = 0.001;
  std::array<std::atomic<double>, kMaxJoints> lag_s_{};
  std::atomic<bool> estop_{false};
  std::array<std::atomic<bool>, kMaxJoints> fault_{};
  std::array<std::atomic<bool>, kMaxJoints> stale_{};
  std::array<std::atomic<bool>, kMaxJoints> min_limit_{};
  std::array<std::atomic<bool>, kMaxJoints> max_limit_{};
  std::array<HomeSwitch, kMaxJoints> home_switch_{};
  // Servo thread only.
  std::array<double, kMaxJoints> commanded_{};
  std::array<double, kMaxJoints> position_{};
  bool primed_ = false;
};

}  // namespace cncd::drivers
