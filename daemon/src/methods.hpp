// The control protocol's methods, bound to a Task.
#pragma once

#include "event_log.hpp"
#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers every method on `dispatcher`; the handlers call into `task` on the server thread.
void register_methods(RpcDispatcher& dispatcher, Task& task, const config::MachineConfig& config,
                      const EventLog& events, Completions& completions);

}  // namespace cncd::daemon
