#include "machine_table.hpp"

#include <cmath>

#include <spdlog/spdlog.h>

#include "cncd/config/enum_name.hpp"

namespace cncd::fleet {

using nlohmann::json;

namespace {

std::vector<std::string> levels(std::string_view text) {
  std::vector<std::string> out;
  for (;;) {
    const auto slash = text.find('/');
    out.emplace_back(text.substr(0, slash));
    if (slash == std::string_view::npos) return out;
    text.remove_prefix(slash + 1);
  }
}

// A topic as the log shows it: printable ASCII, the rest as \xNN, at most 200 bytes.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 200)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    }
  }
  if (text.size() > 200) out += "...";
  return out;
}

const char* refusal_name(MachineTable::Refusal why) {
  static constexpr const char* kNames[] = {
      "payload over the size limit", "topic outside the pattern", "payload not JSON",
      "machine beyond the table's limit", "payload not as expected"};
  return config::enum_name(why, kNames);
}

json number(const json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_number()) return nullptr;
  return std::isfinite(it->get<double>()) ? *it : json(nullptr);
}

const json& field(const json& object, const char* key) {
  static const json null;
  const auto it = object.find(key);
  return it == object.end() ? null : *it;
}

bool is_link(const json& value) {
  if (!value.is_string()) return false;
  const auto& s = value.get_ref<const std::string&>();
  return (s.starts_with("http://") || s.starts_with("https://")) && s.size() <= 1024;
}

}  // namespace

std::string check_pattern(const std::string& pattern) {
  if (pattern.empty() || pattern.front() == '/' || pattern.back() == '/' ||
      pattern.find('#') != std::string::npos || pattern.find('\0') != std::string::npos)
    return "'" + printable(pattern) +
           "' is not a topic pattern: levels and '+', no '#', no '/' at either end (e.g. cncd/+)";
  for (const auto& level : levels(pattern)) {
    if (level.find('+') != std::string::npos && level != "+")
      return "'" + printable(pattern) + "': '+' stands for a whole level";
  }
  return "";
}

std::vector<std::string> topic_filters(const std::string& pattern) {
  return {pattern + "/state", pattern + "/availability", pattern + "/events"};
}

MachineTable::MachineTable(std::string pattern, TableLimits limits)
    : pattern_(levels(pattern)), limits_(limits) {}

bool MachineTable::split(std::string_view topic, std::string& id, std::string& kind) const {
  const auto parts = levels(topic);
  if (parts.size() != pattern_.size() + 1) return false;
  id.clear();
  for (std::size_t i = 0; i < pattern_.size(); ++i) {
    if (pattern_[i] != "+" && pattern_[i] != parts[i]) return false;
    id += (i == 0 ? "" : "/") + parts[i];
  }
  kind = parts.back();
  return !id.empty() && id.size() <= limits_.max_text;
}

MachineTable::Outcome MachineTable::ignore(Refusal why, std::string_view topic,
                                           const std::string& detail) {
  const std::uint64_t n = ++refused_[why];
  if ((n & (n - 1)) == 0)
    spdlog::warn("ignored a message on {}: {}{} ({} such so far)", printable(topic),
                 refusal_name(why), detail.empty() ? "" : ": " + detail, n);
  return Outcome::ignored;
}

void MachineTable::refuse(Refusal why, std::string_view topic, std::size_t bytes) {
  ignore(why, topic, std::to_string(bytes) + " bytes");
}

json MachineTable::text(const json& value) const {
  if (!value.is_string()) return nullptr;
  const auto& s = value.get_ref<const std::string&>();
  return s.size() <= limits_.max_text ? value : json(s.substr(0, limits_.max_text));
}

MachineTable::Outcome MachineTable::apply(std::string_view topic, std::string_view payload,
                                          double now) {
  if (payload.size() > limits_.max_payload)
    return ignore(Refusal::too_large, topic, std::to_string(payload.size()) + " bytes");
  std::string id, kind;
  if (!split(topic, id, kind) || (kind != "state" && kind != "availability" && kind != "events"))
    return ignore(Refusal::bad_topic, topic, "");
  auto found = machines_.find(id);
  if (payload.empty()) {
    // A retained message cleared: the machine leaves once neither state nor availability is left.
    if (found == machines_.end() || kind == "events") return Outcome::unchanged;
    (kind == "state" ? found->second.state : found->second.online) = nullptr;
    if (found->second.state.is_null() && found->second.online.is_null()) machines_.erase(found);
    changed_.insert(id);
    return Outcome::changed;
  }
  json parsed;
  if (kind == "availability") {
    if (payload != "online" && payload != "offline")
      return ignore(Refusal::bad_value, topic, "availability is online or offline");
    parsed = std::string(payload);
  } else {
    parsed = json::parse(payload, nullptr, false);
    if (parsed.is_discarded()) return ignore(Refusal::bad_json, topic, "");
    if (!parsed.is_object()) return ignore(Refusal::bad_value, topic, "not a JSON object");
  }
  if (found == machines_.end()) {
    // Events alone make no row: a machine is known by its state or availability.
    if (kind == "events") return Outcome::unchanged;
    if (machines_.size() >= limits_.max_machines)
      return ignore(Refusal::table_full, topic,
                    "already " + std::to_string(machines_.size()) + " machines");
    found = machines_.emplace(id, Machine{}).first;
  }
  Machine& m = found->second;
  m.seen = now;
  bool changed = false;
  if (kind == "availability") {
    changed = m.online != parsed;
    m.online = parsed;
  } else if (kind == "state") {
    changed = on_state(m, parsed);
  } else {
    changed = on_event(m, parsed);
  }
  if (!changed) return Outcome::unchanged;
  changed_.insert(id);
  return Outcome::changed;
}

bool MachineTable::on_state(Machine& m, const json& s) {
  const json& program = field(s, "program");
  const json empty = json::object();
  const json& p = program.is_object() ? program : empty;
  json row = {{"name", text(field(s, "machine"))},
              {"cncd", text(field(s, "cncd"))},
              {"state", text(field(s, "state"))},
              {"mode", text(field(s, "mode"))},
              {"exec", text(field(s, "exec"))},
              {"program", text(field(p, "path"))},
              {"line", number(p, "line")},
              {"progress", number(p, "progress")},
              {"remaining_s", number(p, "remaining_s")},
              {"estimated_s", number(p, "estimated_s")},
              {"result", text(field(p, "result"))},
              {"parts", number(s, "parts")},
              {"fault", text(field(s, "fault"))},
              {"dashboard", is_link(field(s, "dashboard")) ? field(s, "dashboard") : json()},
              {"time", number(s, "time")}};
  const json& error = field(s, "last_error");
  bool alarm = false;
  if (error.is_object()) {
    json event = error;
    event["level"] = "error";
    alarm = on_event(m, event);
  }
  if (row == m.state) return alarm;
  m.state = std::move(row);
  return true;
}

// An error event, newer than the alarm shown, becomes the last alarm.
bool MachineTable::on_event(Machine& m, const json& e) {
  if (field(e, "level") != "error") return false;
  const json seq = number(e, "seq");
  const json time = number(e, "time");
  if (!m.alarm.is_null()) {
    const json& shown_seq = m.alarm["seq"];
    const json& shown_time = m.alarm["time"];
    if (!seq.is_null() && !shown_seq.is_null() && seq.get<double>() <= shown_seq.get<double>())
      return false;
    if (seq.is_null() && !time.is_null() && !shown_time.is_null() &&
        time.get<double>() <= shown_time.get<double>())
      return false;
  }
  json alarm = {{"seq", seq},
                {"time", time},
                {"kind", text(field(e, "kind"))},
                {"message", text(field(e, "message"))}};
  if (alarm == m.alarm) return false;
  m.alarm = std::move(alarm);
  return true;
}

json MachineTable::row(const std::string& id) const {
  const auto it = machines_.find(id);
  if (it == machines_.end()) return nullptr;
  const Machine& m = it->second;
  json out = m.state.is_object() ? m.state : json::object();
  out["id"] = id;
  if (!out["name"].is_string()) out["name"] = id;
  out["online"] = m.online;
  out["alarm"] = m.alarm;
  out["seen"] = m.seen;
  return out;
}

json MachineTable::rows() const {
  json out = json::array();
  for (const auto& entry : machines_)
    out.push_back(row(entry.first));
  return out;
}

std::vector<std::string> MachineTable::take_changed() {
  std::vector<std::string> out(changed_.begin(), changed_.end());
  changed_.clear();
  return out;
}

std::uint64_t MachineTable::refused(Refusal why) const {
  const auto it = refused_.find(why);
  return it == refused_.end() ? 0 : it->second;
}

std::uint64_t MachineTable::refused_total() const {
  std::uint64_t total = 0;
  for (const auto& entry : refused_)
    total += entry.second;
  return total;
}

}  // namespace cncd::fleet
