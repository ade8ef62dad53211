// [TELEMETRY]: the part count the daemon's job history keeps, and cncd-telemetry's keys (the
// daemon reads them too: one file, checked whole).
#include <string>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

// A key's value without a trailing comment or blanks; "" when absent.
std::string value(TypedReader& r, std::string_view key) {
  return std::string(trim(strip_trailing_comment(r.text("TELEMETRY", key).value_or(""))));
}

// A problem with the value as written: "'VALUE' <why>".
void refuse(TypedReader& r, std::string_view key, const std::string& written,
            std::string_view why) {
  r.problem("TELEMETRY", key, "'" + printable(written) + "' " + std::string(why));
}

bool id_character(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
         c == '_' || c == '.';
}

void load_machine_id(TypedReader& r, const MachineConfig& c, TelemetryConfig& t) {
  const std::string given = value(r, "MACHINE_ID");
  if (!given.empty()) {
    for (const char ch : given) {
      if (!id_character(ch)) {
        refuse(r, "MACHINE_ID", given,
               "may hold only letters, digits, '-', '_' and '.' (it is part of MQTT topics and "
               "metric labels)");
        return;
      }
    }
    t.machine_id = given;
    return;
  }
  std::string id = c.machine_name.empty() ? c.path.stem().string() : c.machine_name;
  for (char& ch : id) {
    if (!id_character(ch)) ch = '_';
  }
  t.machine_id = id.empty() ? "cncd" : id;
}

// ADDRESS:PORT, or "off".
void load_metrics_listen(TypedReader& r, TelemetryConfig& t) {
  const std::string text = value(r, "METRICS_LISTEN");
  if (text == "off") {
    t.metrics_port = 0;
    return;
  }
  const std::size_t colon = text.rfind(':');
  const std::string port = colon == std::string::npos ? "" : text.substr(colon + 1);
  const auto address =
      colon == std::string::npos ? std::nullopt : ip_address(text.substr(0, colon));
  const bool port_ok = !port.empty() && port.size() <= 5 &&
                       port.find_first_not_of("0123456789") == std::string::npos &&
                       std::stoi(port) >= 1 && std::stoi(port) <= 65535;
  if (!address || !port_ok) {
    refuse(r, "METRICS_LISTEN", text,
           "is not ADDRESS:PORT (e.g. 127.0.0.1:9877, [::1]:9877, 0.0.0.0:9877) or off");
    return;
  }
  t.metrics_address = *address;
  t.metrics_port = std::stoi(port);
}

// A topic prefix names levels, never wildcards: '+' and '#' are for subscribers.
void load_topic_prefix(TypedReader& r, TelemetryConfig& t) {
  const std::string given = value(r, "TOPIC_PREFIX");
  if (given.empty()) {
    t.topic_prefix = "cncd/" + t.machine_id;
    return;
  }
  if (given.find_first_of("+#") != std::string::npos || given.front() == '/' ||
      given.back() == '/' || given.find('\0') != std::string::npos) {
    refuse(r, "TOPIC_PREFIX", given,
           "is not a topic prefix: no '+' or '#', no '/' at either end (e.g. shop/bay2/mill-1)");
    return;
  }
  t.topic_prefix = given;
}

}  // namespace

void load_telemetry(TypedReader& r, MachineConfig& c) {
  TelemetryConfig& t = c.telemetry;
  if (const auto v = r.choice("TELEMETRY", "PART_COUNT")) {
    using enum TelemetryConfig::PartCount;
    t.part_count = *v == "m2" ? m2 : *v == "off" ? off : m30;
  }
  load_machine_id(r, c, t);
  load_metrics_listen(r, t);
  const std::string shdr = value(r, "SHDR_LISTEN");
  if (const auto address = ip_address(shdr)) {
    t.shdr_address = *address;
  } else {
    refuse(r, "SHDR_LISTEN", shdr, "is not an IP address (e.g. 127.0.0.1, 0.0.0.0 or ::)");
  }
  if (const auto v = r.integer("TELEMETRY", "SHDR_PORT")) t.shdr_port = static_cast<int>(*v);
  t.mqtt_host = value(r, "MQTT_HOST");
  if (const auto v = r.integer("TELEMETRY", "MQTT_PORT")) t.mqtt_port = static_cast<int>(*v);
  t.mqtt_username = std::string(trim(r.text("TELEMETRY", "MQTT_USERNAME").value_or("")));
  t.mqtt_password = std::string(r.text("TELEMETRY", "MQTT_PASSWORD").value_or(""));
  t.mqtt_tls_ca = r.path("TELEMETRY", "MQTT_TLS_CA").value_or("");
  if (const auto v = r.choice("TELEMETRY", "MQTT_PROTOCOL")) t.mqtt_protocol = *v == "5" ? 5 : 311;
  load_topic_prefix(r, t);
  if (const auto v = r.real("TELEMETRY", "POSITION_HZ")) t.position_hz = *v;
  if (const auto v = r.integer("TELEMETRY", "EVENT_QUEUE")) t.event_queue = static_cast<int>(*v);
  refuse_unknown_keys(r, "TELEMETRY", "cncd's telemetry section");
}

}  // namespace cncd::config
