// [TELEMETRY]: the part count the daemon's job history keeps, and cncd-telemetry's keys (the
// daemon reads them too: one file, checked whole).
#include <unistd.h>

#include <algorithm>
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

// The machine's own dashboard as the fleet page links it: given, "off", or cncd-web's address
// from [WEB] when the INI has that section (a wildcard LISTEN: this host's name).
void load_dashboard_url(TypedReader& r, const MachineConfig& c, TelemetryConfig& t) {
  const std::string given = value(r, "DASHBOARD_URL");
  if (given == "off") return;
  if (!given.empty()) {
    const bool scheme = given.starts_with("http://") || given.starts_with("https://");
    const bool clean = std::none_of(given.begin(), given.end(), [](char ch) {
      return static_cast<unsigned char>(ch) <= ' ' || ch == '"' || ch == '<' || ch == '>' ||
             ch == '\\' || ch == 0x7f;
    });
    if (!scheme || !clean || given.size() > 1024) {
      r.problem("TELEMETRY", "DASHBOARD_URL",
                "'" + printable(given) +
                    "' is not an http:// or https:// URL without blanks, quotes or <> (e.g. "
                    "http://mill-1.shop:8080/), nor off");
      return;
    }
    t.dashboard_url = given;
    return;
  }
  const auto& entries = r.ini().entries();
  if (std::none_of(entries.begin(), entries.end(),
                   [](const auto& entry) { return entry.section == "WEB"; })) {
    return;
  }
  std::string host = c.web.listen;
  if (host == "0.0.0.0" || host == "::") {
    char name[256] = {};
    host = ::gethostname(name, sizeof name - 1) == 0 && name[0] != '\0' ? name : "localhost";
  } else if (host.find(':') != std::string::npos) {
    host = "[" + host + "]";
  }
  t.dashboard_url = std::string(c.web.tls_cert.empty() ? "http://" : "https://") + host + ":" +
                    std::to_string(c.web.port) + "/";
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
  load_dashboard_url(r, c, t);
  refuse_unknown_keys(r, "TELEMETRY", "cncd's telemetry section");
}

}  // namespace cncd::config
