#include "sim_methods.hpp"

#include "cncd/drivers/sim_driver.hpp"
#include "sim_signals.hpp"

namespace cncd::daemon {

using nlohmann::json;

void register_sim_methods(RpcDispatcher& dispatcher, Task& task,
                          const config::MachineConfig& config) {
  dispatcher.add("sim.set", [&task, signals = sim_signals(config)](const json& params) {
    const auto& name = params["signal"].get_ref<const std::string&>();
    const auto it = signals.find(name);
    if (it == signals.end()) {
      throw RpcError(
          kInvalidParams,
          "parameter \"signal\": the machine's INI names no sim signal " + quoted_text(name));
    }
    double value = 0;
    if (const auto error = sim_value(name, it->second, params["value"], value); !error.empty())
      throw RpcError(kInvalidParams, error);
    drivers::SimDriver* sim = task.sim_driver();
    if (sim == nullptr || !sim->set_signal(name, value)) {
      throw RpcError(kInvalidParams,
                     "signal " + quoted_text(name) + ": the machine has no sim driver carrying it");
    }
    return json{{"ok", true}};
  });
}

}  // namespace cncd::daemon
