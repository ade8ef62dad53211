// The JSON of each MQTT message (docs/telemetry.md has their schemas): built from what the
// feed holds, each with the machine's id and the time it was made (Unix seconds).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "machine_feed.hpp"

namespace cncd::telemetry {

// .../state: without "time", so that two can be compared for a change. `dashboard`: the
// machine's own page ([TELEMETRY] DASHBOARD_URL), "" for none.
nlohmann::json state_payload(const MachineFeed& feed, const std::string& machine_id,
                             const nlohmann::json& last_error, const std::string& dashboard);
nlohmann::json position_payload(const MachineFeed& feed, const std::string& machine_id);
// .../events and .../job: cncd's event or job row with the machine's id.
nlohmann::json with_machine(nlohmann::json payload, const std::string& machine_id);
double unix_time();

}  // namespace cncd::telemetry
