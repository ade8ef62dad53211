// The [TELEMETRY] keys of config_keys.cpp's table (not installed): the job history's part
// count, read by cncd, and cncd-telemetry's own.
#pragma once

#include <array>

#include "key_makers.hpp"

namespace cncd::config {

using namespace key_makers;

constexpr std::array kTelemetryKeys{
    choice_key("TELEMETRY", "PART_COUNT", "m30", "m30|m2|off",
               "Which program end counts a part in the job history: m30 (M30 only), m2 (M2 or "
               "M30) or off"),
    text_key("TELEMETRY", "MACHINE_ID", "",
             "The machine's name in MQTT topics, MTConnect and metrics (letters, digits, - _ .); "
             "empty: [EMC] MACHINE with other characters as _, else the INI's name"),
    text_key("TELEMETRY", "METRICS_LISTEN", "127.0.0.1:9877",
             "cncd-telemetry: ADDRESS:PORT of the Prometheus /metrics endpoint; off: none"),
    text_key("TELEMETRY", "SHDR_LISTEN", "127.0.0.1",
             "cncd-telemetry: the address the MTConnect SHDR adapter listens on"),
    integer_key("TELEMETRY", "SHDR_PORT", "7878", 0, 65535, "",
                "cncd-telemetry: the SHDR adapter's TCP port; 0: none"),
    text_key("TELEMETRY", "MQTT_HOST", "",
             "cncd-telemetry: the MQTT broker's host name or address; empty: no MQTT"),
    integer_key("TELEMETRY", "MQTT_PORT", "1883", 1, 65535, "",
                "cncd-telemetry: the broker's port"),
    text_key("TELEMETRY", "MQTT_USERNAME", "", "cncd-telemetry: the broker's user name"),
    text_key("TELEMETRY", "MQTT_PASSWORD", "",
             "cncd-telemetry: the broker's password (keep the INI unreadable to others then)"),
    path_key("TELEMETRY", "MQTT_TLS_CA", "",
             "cncd-telemetry: a CA certificate file: the broker is reached over TLS"),
    choice_key("TELEMETRY", "MQTT_PROTOCOL", "5", "5|3.1.1", "cncd-telemetry: the MQTT version"),
    text_key("TELEMETRY", "TOPIC_PREFIX", "",
             "cncd-telemetry: the topics' prefix; empty: cncd/<MACHINE_ID>"),
    real_key("TELEMETRY", "POSITION_HZ", "5", 0, 100, "Hz",
             "cncd-telemetry: position messages a second; 0: none"),
    integer_key("TELEMETRY", "EVENT_QUEUE", "10000", 1, 10000000, "",
                "cncd-telemetry: events and jobs kept while the broker is away; beyond, the "
                "oldest are dropped, counted and logged"),
    text_key("TELEMETRY", "DASHBOARD_URL", "",
             "cncd-telemetry: the machine's own dashboard as the fleet page links it (http:// or "
             "https://); empty: cncd-web's address from [WEB] when the INI has that section; "
             "off: none"),
};

}  // namespace cncd::config
