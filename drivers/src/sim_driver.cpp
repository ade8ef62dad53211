#include "cncd/drivers/sim_driver.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "cncd/drivers/fault_reason.hpp"

#include "ini_lookup.hpp"
#include "panel_wiring.hpp"

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
  // Every sim address gets a slot; an output and an input of the same name share it.
  std::vector<std::string> names;
  const auto slot = [&](const config::SignalAddress& a) -> int {
    if (a.kind != config::SignalAddress::Kind::sim) return -1;
    const auto at = std::find(names.begin(), names.end(), a.name);
    if (at != names.end()) return static_cast<int>(at - names.begin());
    names.push_back(a.name);
    return static_cast<int>(names.size()) - 1;
  };
  const config::IoConfig& io = machine.io;
  flood_ = slot(io.flood);
  mist_ = slot(io.mist);
  for (std::size_t n = 0; n < digital_out_.size(); ++n)
    digital_out_[n] = slot(io.digital_outputs[n]);
  for (std::size_t n = 0; n < analog_out_.size(); ++n)
    analog_out_[n] = slot(io.analog_outputs[n]);
  for (std::size_t n = 0; n < digital_in_.size(); ++n)
    digital_in_[n] = slot(io.digital_inputs[n]);
  for (std::size_t n = 0; n < analog_in_.size(); ++n)
    analog_in_[n] = slot(io.analog_inputs[n]);
  probe_signal_ = slot(io.probe_input);
  const config::PanelConfig& panel = machine.panel;
  for (std::size_t i = 0; i < panel_in_.size(); ++i)
    panel_in_[i] = slot(panel.inputs[i]);
  for (int c = 0; c < config::kPanelCounters; ++c) {
    const config::PanelCounterWiring& wiring = panel_counter_wiring(panel, c);
    PanelCounter& counter = panel_counters_[static_cast<std::size_t>(c)];
    counter.counts = slot(wiring.counts);
    counter.a = slot(wiring.a);
    counter.b = slot(wiring.b);
    if ((counter.a >= 0) != (counter.b >= 0)) {
      return std::string("[PANEL] ") + panel_counter_key(c) + "_A and " + panel_counter_key(c) +
             "_B: an encoder on sim signals needs both A and B as sim:NAME";
    }
    counter.decoder = QuadratureCounter{};
    counter.errors.store(0);
  }
  for (int k = 0; k < config::kPanelAnalogs; ++k)
    panel_analog_[static_cast<std::size_t>(k)] = slot(panel_analog_address(panel, k));
  for (std::size_t l = 0; l < panel_light_.size(); ++l)
    panel_light_[l] = slot(panel.lights[l]);
  signal_count_ = names.size();
  signals_ = std::make_unique<Signal[]>(std::max<std::size_t>(1, signal_count_));
  for (std::size_t k = 0; k < signal_count_; ++k)
    signals_[k].name = names[k];

  // The probe model, for the driver that has the Z joint.
  probe_model_ = false;
  probe_joint_ = {-1, -1, -1};
  if (ini.has("SIM", "PROBE_SURFACE_Z")) {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const char axis = machine.joints[static_cast<std::size_t>(joints[i])].axis;
      const int k = axis == 'X' ? 0 : axis == 'Y' ? 1 : axis == 'Z' ? 2 : -1;
      if (k >= 0 && probe_joint_[static_cast<std::size_t>(k)] < 0)
        probe_joint_[static_cast<std::size_t>(k)] = static_cast<int>(i);
    }
    probe_model_ = probe_joint_[2] >= 0;
    probe_top_ = ini.real("SIM", "PROBE_SURFACE_Z");
    const auto bound = [&](const char* key, double& value) {
      if (ini.has("SIM", key)) value = ini.real("SIM", key);
    };
    bound("PROBE_X_MIN", probe_x_min_);
    bound("PROBE_X_MAX", probe_x_max_);
    bound("PROBE_Y_MIN", probe_y_min_);
    bound("PROBE_Y_MAX", probe_y_max_);
    if (!ini.error().empty()) return ini.error();
    if (probe_x_min_ > probe_x_max_ || probe_y_min_ > probe_y_max_) {
      return "[SIM] PROBE_X_MIN/PROBE_Y_MIN must not exceed PROBE_X_MAX/PROBE_Y_MAX";
    }
  }

  const config::SpindleConfig& spindle = machine.spindle;
  spindle_ = spindle.present && spindle.driver == config::SpindleDriver::sim;
  if (spindle_ && spindle.acceleration < 0) {
    return "[SPINDLE_0] ACCELERATION must not be negative (0 = at once)";
  }
  spindle_model_.reset(spindle.acceleration, period_s_);
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
  const int forced = probe_forced_.load(std::memory_order_relaxed);
  if (forced >= 0) {
    if (forced > 0) inputs.probe = true;
    return;
  }
  if (probe_signal_ >= 0 && load(probe_signal_) != 0) inputs.probe = true;
  if (!probe_model_) return;
  const auto at = [&](int k, double otherwise) {
    const int i = probe_joint_[static_cast<std::size_t>(k)];
    return i >= 0 ? position_[static_cast<std::size_t>(i)] : otherwise;
  };
  const double x = at(0, 0);
  const double y = at(1, 0);
  const double z = at(2, 0);
  const bool inside = z <= probe_top_ && x >= probe_x_min_ && x <= probe_x_max_ &&
                      y >= probe_y_min_ && y <= probe_y_max_;
  if (inside) inputs.probe = true;
}

void SimDriver::store(int index, double value) noexcept {
  if (index >= 0)
    signals_[static_cast<std::size_t>(index)].value.store(value, std::memory_order_relaxed);
}

double SimDriver::load(int index) const noexcept {
  return index >= 0
             ? signals_[static_cast<std::size_t>(index)].value.load(std::memory_order_relaxed)
             : 0.0;
}

void SimDriver::write_io(const IoCommand& command) noexcept {
  spindle_model_.command(command.spindle);
  store(flood_, command.flood ? 1 : 0);
  store(mist_, command.mist ? 1 : 0);
  for (std::size_t n = 0; n < digital_out_.size(); ++n)
    store(digital_out_[n], (command.digital >> n) & 1u ? 1 : 0);
  for (std::size_t n = 0; n < analog_out_.size(); ++n)
    store(analog_out_[n], command.analog[n]);
  for (std::size_t l = 0; l < panel_light_.size(); ++l)
    store(panel_light_[l], (command.panel >> l) & 1u ? 1 : 0);
}

void SimDriver::read_panel(PanelFeedback& panel) noexcept {
  for (std::size_t i = 0; i < panel_in_.size(); ++i) {
    if (panel_in_[i] >= 0)
      panel.inputs = with_bit(panel.inputs, static_cast<int>(i), load(panel_in_[i]) != 0);
  }
  for (std::size_t c = 0; c < panel_counters_.size(); ++c) {
    PanelCounter& counter = panel_counters_[c];
    if (counter.counts >= 0) {
      // A counter as a 32-bit register would hold it: whole counts, wrapping.
      const double value = load(counter.counts);
      const bool usable = std::isfinite(value) && std::abs(value) < 9e18;
      panel.counts[c] = usable ? static_cast<std::uint32_t>(std::llround(value)) : 0;
      panel.counter_bits[c] = 32;
    } else if (counter.a >= 0) {
      counter.decoder.sample(load(counter.a) != 0, load(counter.b) != 0);
      counter.errors.store(counter.decoder.errors(), std::memory_order_relaxed);
      panel.counts[c] = counter.decoder.count();
      panel.counter_bits[c] = 32;
    }
  }
  for (std::size_t k = 0; k < panel_analog_.size(); ++k) {
    if (panel_analog_[k] >= 0) panel.analog[k] = load(panel_analog_[k]);
  }
}

void SimDriver::simulate_spindle(IoFeedback& feedback) noexcept {
  SpindleFeedback& fb = feedback.spindle;
  fb.present = true;
  fb.fault = spindle_fault_.load(std::memory_order_relaxed);
  fb.stale = spindle_stale_.load(std::memory_order_relaxed);
  fb.has_at_speed = false;
  fb.at_speed = false;
  // The stand-in for an encoder: revolutions count the simulated position, signed.
  fb.has_position = true;
  spindle_model_.step(fb, fb.stale);
}

void SimDriver::read_io(IoFeedback& feedback) noexcept {
  if (spindle_) simulate_spindle(feedback);
  for (std::size_t n = 0; n < digital_in_.size(); ++n) {
    if (digital_in_[n] < 0) continue;
    const std::uint32_t bit = 1u << n;
    feedback.digital = load(digital_in_[n]) != 0 ? feedback.digital | bit : feedback.digital & ~bit;
  }
  for (std::size_t n = 0; n < analog_in_.size(); ++n) {
    if (analog_in_[n] >= 0) feedback.analog[n] = load(analog_in_[n]);
  }
  read_panel(feedback.panel);
}

SimDriver::Signal* SimDriver::find(std::string_view name) const {
  for (std::size_t k = 0; k < signal_count_; ++k) {
    if (signals_[k].name == name) return &signals_[k];
  }
  return nullptr;
}

std::optional<double> SimDriver::signal_value(std::string_view name) const {
  const Signal* s = find(name);
  if (s == nullptr) return std::nullopt;
  return s->value.load();
}

bool SimDriver::signal_on(std::string_view name) const {
  return signal_value(name).value_or(0) != 0;
}

bool SimDriver::set_signal(std::string_view name, double value) {
  Signal* s = find(name);
  if (s == nullptr) return false;
  s->value.store(value);
  return true;
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
  if (spindle_ && spindle_fault_.load(std::memory_order_relaxed)) {
    copy_text(out, size, "fault injected on the simulated spindle ([SPINDLE_0] DRIVER = sim)");
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
