// The setup methods (tool table and coordinate systems), bound to a Task.
#pragma once

#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers tool.list, tool.set, offsets.get and offsets.set; handlers run on the server thread.
void register_setup_methods(RpcDispatcher& dispatcher, Task& task,
                            const config::MachineConfig& config);

}  // namespace cncd::daemon
