// sim.set: the `sim:` signals a machine's INI names, by what they carry, and the values each
// takes (docs/protocol.md, "sim.set").
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "cncd/config/machine_config.hpp"

namespace cncd::daemon {

enum class SimSignalKind {
  digital_input,  // a button, switch, A/B encoder line or DIGITAL_INPUT_n: 0 or 1
  counter,        // MPG_COUNTS, <NAME>_OVERRIDE_COUNTS: an integer
  analog_input,   // ANALOG_INPUT_n, <NAME>_OVERRIDE_ANALOG: a finite number
  output,         // driven by the machine (coolant, outputs, lamps): not set from outside
};

// Every `sim:` signal of `config` by name. A name used for an input and an output (wired back
// to back) is the input.
std::map<std::string, SimSignalKind> sim_signals(const config::MachineConfig& config);

// The value `value` as signal `name` of `kind` takes it, or "" and the number in `out`; else
// the error message naming the signal.
std::string sim_value(const std::string& name, SimSignalKind kind, const nlohmann::json& value,
                      double& out);

}  // namespace cncd::daemon
