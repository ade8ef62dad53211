// The Prometheus text exposition (format 0.0.4) of what the feed knows: names and units after
// Prometheus' conventions (seconds, ratios, _total for counters), every series labelled with
// the machine's id. docs/telemetry.md lists each metric.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

#include "machine_feed.hpp"

namespace cncd::telemetry {

// What the telemetry process counts itself, beside the feed.
struct Counters {
  std::map<std::pair<std::string, std::string>, std::uint64_t> events;  // (level, kind) -> n
  std::map<std::string, std::uint64_t> faults;  // the servo thread's fault code -> n
  // The MQTT publisher's own state, when there is one ([TELEMETRY] MQTT_HOST).
  bool mqtt = false;
  bool mqtt_connected = false;
  std::size_t mqtt_queued = 0;
  std::uint64_t mqtt_dropped = 0;
};

std::string prometheus_text(const MachineFeed& feed, const Counters& counters,
                            const std::string& machine_id);

}  // namespace cncd::telemetry
