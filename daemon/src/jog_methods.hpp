// jog.start, jog.stop, jog.increment and jog.heartbeat, bound to a Task.
#pragma once

#include "jog_heartbeat.hpp"
#include "rpc.hpp"
#include "task.hpp"

namespace cncd::daemon {

// Registers the jog methods (control group); handlers run on the server thread.
// `heartbeats` watches the jogs started with "heartbeat_s", for `events`' actor.
void register_jog_methods(RpcDispatcher& dispatcher, Task& task,
                          const config::MachineConfig& config, JogHeartbeats& heartbeats,
                          const EventLog& events);

}  // namespace cncd::daemon
