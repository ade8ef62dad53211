// The control protocol's methods, bound to a Task.
#pragma once

#include "event_log.hpp"
#include "rpc.hpp"
#include "status_cache.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers every method on `dispatcher`; the handlers call into `task` on the server thread.
// status.get answers from `status` when given (shared with the server's subscriptions), else
// builds the status for each request.
void register_methods(RpcDispatcher& dispatcher, Task& task, const config::MachineConfig& config,
                      const EventLog& events, Completions& completions,
                      StatusCache* status = nullptr);

}  // namespace cncd::daemon
