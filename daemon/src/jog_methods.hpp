// jog.start, jog.stop and jog.increment, bound to a Task.
#pragma once

#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers the jog methods (control group); handlers run on the server thread.
void register_jog_methods(RpcDispatcher& dispatcher, Task& task,
                          const config::MachineConfig& config);

}  // namespace cncd::daemon
