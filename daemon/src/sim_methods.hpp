// sim.set: an input of the simulated machine set from outside, to rehearse a panel without
// hardware (docs/protocol.md, "sim.set").
#pragma once

#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

void register_sim_methods(RpcDispatcher& dispatcher, Task& task,
                          const config::MachineConfig& config);

}  // namespace cncd::daemon
