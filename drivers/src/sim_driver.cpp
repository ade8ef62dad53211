#include "cncd/drivers/sim_driver.hpp"

#include <cmath>
#include <cstring>

#include "cncd/drivers/fault_reason.hpp"

#include "ini_lookup.hpp"

namespace cncd::drivers {

std::string SimDriver::configure(const config::MachineConfig& machine,
                                 const std::vector<int>& joints) {
  if (joints.size() > static_cast<std::size_t>(kMaxJoints)) return "too many joints for one driver";
  if (machine.servo_period_ns <= 0) return "the servo period must be positive";
  period_s_ = static_cast<double>(machine.servo_period_ns) * 1e-9;
  IniLookup ini(machine);
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const int j = joints[i];
    if (j < 0 || static_cast<std::size_t>(j) >= machine.joints.size()) {
      return "joint " + std::to_string(j) + " is not in the configuration";
    }
    lag_s_[i].store(ini.real(joint_section(j), "SIM_LAG"));
    if (!ini.error().empty()) return ini.error();
    const auto& joint = machine.joints[static_cast<std::size_t>(j)];
    const int direction = joint.home_search_vel > 0 ? 1 : joint.home_search_vel < 0 ? -1 : 0;
    set_home_switch(static_cast<int>(i), joint.home_offset, direction);
  }
  return "";
}

void SimDriver::write(const JointCommand* commands, int count) noexcept {
  for (int i = 0; i < count && i < kMaxJoints; ++i) {
    commanded_[static_cast<std::size_t>(i)] = commands[i].position;
    if (!primed_) position_[static_cast<std::size_t>(i)] = commands[i].position;
  }
  primed_ = true;
}

void SimDriver::read(JointFeedback* feedback, int count) noexcept {
  for (int i = 0; i < count && i < kMaxJoints; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double lag = lag_s_[k].load(std::memory_order_relaxed);
    // Exact discretization of a first-order lag: stable for any period.
    const double alpha = lag > 0 ? 1.0 - std::exp(-period_s_ / lag) : 1.0;
    feedback[i].stale = stale_[k].load(std::memory_order_relaxed);
    feedback[i].fault = fault_[k].load(std::memory_order_relaxed);
    if (!feedback[i].stale) position_[k] += (commanded_[k] - position_[k]) * alpha;
    feedback[i].position = position_[k];
    const int direction = home_switch_[k].direction.load(std::memory_order_acquire);
    const double at = home_switch_[k].position.load(std::memory_order_relaxed);
    feedback[i].home_switch =
        (direction > 0 && position_[k] >= at) || (direction < 0 && position_[k] <= at);
    feedback[i].min_limit = min_limit_[k].load(std::memory_order_relaxed);
    feedback[i].max_limit = max_limit_[k].load(std::memory_order_relaxed);
  }
}

void SimDriver::read_inputs(MachineInputs& inputs) noexcept {
  if (estop_.load(std::memory_order_relaxed)) inputs.estop = true;
}

bool SimDriver::fault_reason(char* out, std::size_t size) const noexcept {
  if (size == 0) return false;
  out[0] = '\0';
  for (int i = 0; i < kMaxJoints; ++i) {
    if (!fault_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed)) continue;
    // Put together by hand: the servo thread asks, and it formats nothing.
    char text[48] = "fault injected on simulated drive ";
    std::size_t n = std::strlen(text);
    if (i >= 10) text[n++] = static_cast<char>('0' + i / 10);
    text[n++] = static_cast<char>('0' + i % 10);
    text[n] = '\0';
    copy_text(out, size, text);
    return true;
  }
  return false;
}

void SimDriver::set_lag(double time_constant_s) noexcept {
  for (auto& lag : lag_s_)
    lag.store(time_constant_s);
}

void SimDriver::set_fault(int index, bool fault) noexcept {
  if (valid(index)) fault_[static_cast<std::size_t>(index)].store(fault);
}

void SimDriver::set_stale(int index, bool stale) noexcept {
  if (valid(index)) stale_[static_cast<std::size_t>(index)].store(stale);
}

void SimDriver::set_limit(int index, bool min_limit, bool max_limit) noexcept {
  if (!valid(index)) return;
  min_limit_[static_cast<std::size_t>(index)].store(min_limit);
  max_limit_[static_cast<std::size_t>(index)].store(max_limit);
}

void SimDriver::set_home_switch(int index, double position, int direction) noexcept {
  if (!valid(index)) return;
  auto& s = home_switch_[static_cast<std::size_t>(index)];
  // Direction last: a reader that sees the new direction also sees the new position.
  s.position.store(position);
  s.direction.store(direction);
}

}  // namespace cncd::drivers
