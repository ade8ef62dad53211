#include "sim_signals.hpp"

#include <cmath>

#include "rpc_params.hpp"  // quoted_text

namespace cncd::daemon {

std::map<std::string, SimSignalKind> sim_signals(const config::MachineConfig& config) {
  std::map<std::string, SimSignalKind> out;
  const auto add = [&out](const config::SignalAddress& address, SimSignalKind kind) {
    if (address.kind != config::SignalAddress::Kind::sim) return;
    auto [at, added] = out.emplace(address.name, kind);
    if (!added && at->second == SimSignalKind::output) at->second = kind;
  };
  const config::IoConfig& io = config.io;
  add(io.flood, SimSignalKind::output);
  add(io.mist, SimSignalKind::output);
  for (const auto& address : io.digital_outputs)
    add(address, SimSignalKind::output);
  for (const auto& address : io.analog_outputs)
    add(address, SimSignalKind::output);
  for (const auto& address : io.digital_inputs)
    add(address, SimSignalKind::digital_input);
  for (const auto& address : io.analog_inputs)
    add(address, SimSignalKind::analog_input);
  add(io.probe_input, SimSignalKind::digital_input);
  const config::PanelConfig& panel = config.panel;
  for (const auto& address : panel.inputs)
    add(address, SimSignalKind::digital_input);
  const auto counter = [&add](const config::PanelCounterWiring& wiring) {
    add(wiring.a, SimSignalKind::digital_input);
    add(wiring.b, SimSignalKind::digital_input);
    add(wiring.counts, SimSignalKind::counter);
  };
  counter(panel.mpg);
  for (const auto& knob : panel.knobs) {
    counter(knob.encoder);
    add(knob.analog, SimSignalKind::analog_input);
  }
  for (const auto& address : panel.lights)
    add(address, SimSignalKind::output);
  return out;
}

std::string sim_value(const std::string& name, SimSignalKind kind, const nlohmann::json& value,
                      double& out) {
  const std::string signal = "signal " + quoted_text(name);
  if (!value.is_number()) return "parameter \"value\" of " + signal + " must be a number";
  const double v = value.get<double>();
  switch (kind) {
    case SimSignalKind::output:
      return signal + " is an output: the machine sets it";
    case SimSignalKind::digital_input:
      if (!value.is_number_integer() || (v != 0 && v != 1))
        return "parameter \"value\" of " + signal + " (a digital input) must be 0 or 1";
      break;
    case SimSignalKind::counter:
      // A counter wraps at 32 bits: any 32-bit value, signed or not.
      if (!value.is_number_integer() || v < -2147483648.0 || v > 4294967295.0) {
        return "parameter \"value\" of " + signal +
               " (a counter) must be an integer from -2147483648 to 4294967295";
      }
      break;
    case SimSignalKind::analog_input:
      if (!std::isfinite(v))
        return "parameter \"value\" of " + signal + " (an analog input) must be a finite number";
      break;
  }
  out = v;
  return "";
}

}  // namespace cncd::daemon
