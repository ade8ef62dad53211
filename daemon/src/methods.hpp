// The control protocol's methods, bound to a Task.
#pragma once

#include "event_log.hpp"
#include "jog_heartbeat.hpp"
#include "rpc.hpp"
#include "status_cache.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers every method on `dispatcher`; the handlers call into `task` on the server thread.
// status.get answers from `status` when given (shared with the server's subscriptions), else
// builds the status for each request.
// `heartbeats` watches the jogs started with a heartbeat.
void register_methods(RpcDispatcher& dispatcher, Task& task, const config::MachineConfig& config,
                      const EventLog& events, Completions& completions, JogHeartbeats& heartbeats,
                      StatusCache* status = nullptr);

}  // namespace cncd::daemon
