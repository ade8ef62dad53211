#include "payloads.hpp"

#include <chrono>

#include "json_read.hpp"

namespace cncd::telemetry {

using nlohmann::json;

namespace {

json number_or_null(const json& object, const char* key) {
  if (object.is_object()) {
    const auto it = object.find(key);
    if (it != object.end() && it->is_number()) return *it;
  }
  return nullptr;
}

}  // namespace

double unix_time() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

json state_payload(const MachineFeed& feed, const std::string& machine_id, const json& last_error,
                   const std::string& dashboard) {
  const json& s = feed.status();
  const json link = dashboard.empty() ? json(nullptr) : json(dashboard);
  if (!feed.connected() || !s.contains("state"))
    return {{"machine", machine_id}, {"cncd", "unreachable"}, {"dashboard", link}};
  const json& program = object_at(s, "program");
  const json& spindle = object_at(s, "spindle");
  const json& tool = object_at(s, "tool");
  return {{"machine", machine_id},
          {"cncd", "connected"},
          {"state", text_at(s, "state")},
          {"mode", text_at(s, "mode")},
          {"exec", text_at(s, "exec")},
          {"program",
           {{"path", text_at(program, "path")},
            {"line", number_at(program, "line")},
            {"total_lines", number_at(program, "total_lines")},
            {"progress", number_at(program, "progress")},
            {"estimated_s", number_or_null(program, "estimated_s")},
            {"remaining_s", number_or_null(program, "remaining_s")},
            {"result", text_at(program, "result")}}},
          {"tool", number_at(tool, "number")},
          {"spindle",
           {{"rpm", number_at(spindle, "actual_rpm")},
            {"commanded_rpm", number_at(spindle, "commanded_rpm")},
            {"direction", number_at(spindle, "direction")}}},
          {"overrides", object_at(s, "overrides")},
          {"wait", s.contains("wait") ? s["wait"] : json(nullptr)},
          {"fault", text_at(s, "fault")},
          {"last_error", last_error},
          {"parts", number_or_null(feed.jobs(), "parts")},
          {"dashboard", link}};
}

json position_payload(const MachineFeed& feed, const std::string& machine_id) {
  const json& s = feed.status();
  return {{"machine", machine_id},
          {"time", unix_time()},
          {"machine_position", object_at(object_at(s, "position"), "actual")},
          {"work_position", object_at(object_at(s, "work_position"), "actual")},
          {"velocity", number_at(s, "velocity")}};
}

json with_machine(json payload, const std::string& machine_id) {
  if (payload.is_object()) payload["machine"] = machine_id;
  return payload;
}

}  // namespace cncd::telemetry
