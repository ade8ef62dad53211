// The task's reports as the control protocol's JSON (docs/protocol.md: status.get, tool.list,
// offsets.get, errors.list). Positions and offsets are objects keyed by the machine's axes, in
// lower case.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/tool_entry.hpp"
#include "event_log.hpp"
#include "task_report.hpp"

namespace cncd::daemon {

// `clients`: the connections to the control socket (the server's count).
nlohmann::json status_json(const TaskStatus& status, const config::MachineConfig& config,
                           std::size_t clients);
nlohmann::json tool_list_json(const std::vector<interp::ToolEntry>& tools,
                              const config::MachineConfig& config);
nlohmann::json offsets_json(const OffsetsReport& offsets, const config::MachineConfig& config);
// One entry of the event log, as errors.list lists it and the "event" notification carries it.
nlohmann::json event_json(const Event& event);
// The number, or null when there is none.
nlohmann::json optional_number(const std::optional<double>& value);
// Events as errors.list lists them, oldest first.
nlohmann::json events_json(const std::vector<Event>& events);

}  // namespace cncd::daemon
