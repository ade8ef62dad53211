// override.feed, override.rapid and override.spindle, bound to a Task.
#pragma once

#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers the override methods (control group); handlers run on the server thread.
void register_override_methods(RpcDispatcher& dispatcher, Task& task,
                               const config::MachineConfig& config);

}  // namespace cncd::daemon
