#include "panel_rules.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cncd::daemon {

namespace {

using config::PanelInput;

PanelVerdict cycle_start(const PanelSituation& now) {
  if (now.door_open) return {PanelAct::refused, "the door is open: close it first"};
  switch (now.exec) {
    case ExecState::idle:
      if (now.opening) {
        return {PanelAct::refused, "the program is still being checked: start it once it is open"};
      }
      if (!now.program_open) return {PanelAct::refused, "no program is open"};
      return {now.single_block ? PanelAct::step : PanelAct::run, ""};
    case ExecState::paused:
      return {now.single_block ? PanelAct::step : PanelAct::resume, ""};
    case ExecState::running:
      break;
  }
  if (now.mode == Mode::mdi) return {PanelAct::refused, "an MDI command is running"};
  return {PanelAct::refused,
          now.stepping ? "the last step is still running" : "the program is already running"};
}

}  // namespace

PanelVerdict press_verdict(PanelInput input, const PanelSituation& now) {
  if (input == PanelInput::machine_on) {
    if (now.machine == motion::MachineState::estop)
      return {PanelAct::refused, "the machine is in estop: reset it first"};
    return {now.machine == motion::MachineState::off ? PanelAct::machine_on : PanelAct::none, ""};
  }
  if (input == PanelInput::reset) {
    return {now.machine == motion::MachineState::estop ? PanelAct::reset : PanelAct::none, ""};
  }
  if (now.machine == motion::MachineState::estop)
    return {PanelAct::ignored, "the machine is in estop"};
  if (now.machine == motion::MachineState::off) return {PanelAct::ignored, "the machine is off"};
  switch (input) {
    case PanelInput::cycle_start:
      return cycle_start(now);
    case PanelInput::feed_hold:
      if (now.exec == ExecState::running) return {PanelAct::pause, ""};
      return {PanelAct::refused, now.exec == ExecState::paused ? "the program is already paused"
                                                               : "no program is running"};
    case PanelInput::stop:
      return {PanelAct::abort, ""};
    default:
      return {PanelAct::none, ""};
  }
}

const char* panel_act_method(PanelAct act) {
  static constexpr const char* kMethods[] = {"program.run",   "program.step",  "program.resume",
                                             "program.pause", "program.abort", "machine.on",
                                             "machine.reset"};
  if (act < PanelAct::run) return "";  // none, ignored, refused: nothing to call
  return kMethods[static_cast<std::size_t>(act) - static_cast<std::size_t>(PanelAct::run)];
}

std::uint32_t panel_light_bits(motion::MachineState machine, bool fault, ExecState exec,
                               bool waiting) {
  const auto bit = [](config::PanelLight light) {
    return std::uint32_t{1} << static_cast<unsigned>(light);
  };
  std::uint32_t out = 0;
  if (machine == motion::MachineState::estop || fault) out |= bit(config::PanelLight::red);
  if (exec == ExecState::paused || (exec == ExecState::running && waiting))
    out |= bit(config::PanelLight::amber);
  if (exec == ExecState::running) {
    out |= bit(config::PanelLight::lamp_cycle_start);
    if (!waiting) out |= bit(config::PanelLight::green);
  }
  if (exec == ExecState::paused) out |= bit(config::PanelLight::lamp_feed_hold);
  return out;
}

double knob_override(double value, double analog_min, double analog_max, double low, double high) {
  if (!std::isfinite(value) || !(analog_max > analog_min))
    return std::numeric_limits<double>::quiet_NaN();
  const double t = std::clamp((value - analog_min) / (analog_max - analog_min), 0.0, 1.0);
  return low + t * (high - low);
}

double counted_override(double current, std::int64_t counts, double per_count, double low,
                        double high) {
  return std::clamp(current + static_cast<double>(counts) * per_count, low, high);
}

}  // namespace cncd::daemon
