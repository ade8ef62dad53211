// tool.list, tool.set, offsets.get, offsets.set: parameter checks and the calls into Task.
#include "setup_methods.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <string>

namespace cncd::daemon {

using nlohmann::json;

namespace {

const json& object_params(const json& params) {
  static const json empty = json::object();
  if (params.is_null()) return empty;
  if (!params.is_object()) throw RpcError(kInvalidParams, "params must be an object");
  return params;
}

void allow_only(const json& params, std::initializer_list<const char*> names) {
  for (const auto& [key, value] : params.items()) {
    bool known = false;
    for (const char* name : names)
      known = known || key == name;
    if (!known) throw RpcError(kInvalidParams, "unknown parameter \"" + key + "\"");
  }
}

double finite_number(const json& value, const std::string& name, double min, double max) {
  if (!value.is_number()) throw RpcError(kInvalidParams, "\"" + name + "\" must be a number");
  const double v = value.get<double>();
  if (!std::isfinite(v) || v < min || v > max) {
    throw RpcError(kInvalidParams,
                   "\"" + name + "\" must be from " + json(min).dump() + " to " + json(max).dump());
  }
  return v;
}

int integer(const json& value, const std::string& name, int min, int max) {
  if (!value.is_number_integer() || value.get<std::int64_t>() < min ||
      value.get<std::int64_t>() > max) {
    throw RpcError(kInvalidParams, "\"" + name + "\" must be an integer from " +
                                       std::to_string(min) + " to " + std::to_string(max));
  }
  return value.get<int>();
}

// {"x": 1.5, "z": -2} for the machine's axes; sets the bits of the axes named in `mask`.
void read_axes(const json& value, const std::string& name, const config::MachineConfig& config,
               interp::Pose& pose, std::uint32_t& mask) {
  if (!value.is_object()) {
    throw RpcError(kInvalidParams, "\"" + name + "\" must be an object of axis values");
  }
  constexpr double kLimit = 1e9;
  for (const auto& [key, number] : value.items()) {
    const auto index = key.size() == 1 ? config::kAxisLetters.find(static_cast<char>(
                                             std::toupper(static_cast<unsigned char>(key[0]))))
                                       : std::string_view::npos;
    if (index == std::string_view::npos || !config.axes[index].present) {
      throw RpcError(kInvalidParams,
                     "\"" + name + "\" names axis \"" + key + "\", which this machine lacks");
    }
    pose[index] = finite_number(number, name + "." + key, -kLimit, kLimit);
    mask |= 1U << index;
  }
}

// "G54" .. "G59.3" or 1 .. 9.
int coord_system(const json& value) {
  if (value.is_number_integer()) return integer(value, "system", 1, 9);
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    for (int system = 1; system <= 9; ++system) {
      const std::string known = coord_system_name(system);
      if (name.size() == known.size() &&
          std::equal(name.begin(), name.end(), known.begin(),
                     [](char a, char b) { return std::toupper(a) == b; }))
        return system;
    }
  }
  throw RpcError(kInvalidParams, "\"system\" must be one of G54 .. G59.3 (or 1 .. 9)");
}

interp::ToolEntry tool_from_params(const json& p, const Task& task,
                                   const config::MachineConfig& config) {
  allow_only(p, {"number", "pocket", "offset", "diameter", "front_angle", "back_angle",
                 "orientation", "comment"});
  if (!p.contains("number")) throw RpcError(kInvalidParams, "\"number\" is missing");
  const int number = integer(p["number"], "number", 1, 99999);
  interp::ToolEntry entry;
  if (const auto existing = task.find_tool(number)) {
    entry = *existing;
  } else {
    entry.number = number;
    entry.pocket = number;
  }
  if (p.contains("pocket")) entry.pocket = integer(p["pocket"], "pocket", 1, 99999);
  if (p.contains("offset")) {
    std::uint32_t mask = 0;
    read_axes(p["offset"], "offset", config, entry.offset, mask);
  }
  if (p.contains("diameter")) entry.diameter = finite_number(p["diameter"], "diameter", 0, 1e6);
  if (p.contains("front_angle"))
    entry.front_angle = finite_number(p["front_angle"], "front_angle", -360, 360);
  if (p.contains("back_angle"))
    entry.back_angle = finite_number(p["back_angle"], "back_angle", -360, 360);
  if (p.contains("orientation")) entry.orientation = integer(p["orientation"], "orientation", 0, 9);
  if (p.contains("comment")) {
    if (!p["comment"].is_string()) throw RpcError(kInvalidParams, "\"comment\" must be a string");
    const std::string comment = p["comment"].get<std::string>();
    if (comment.size() > 200 || comment.find_first_of("\r\n") != std::string::npos) {
      throw RpcError(kInvalidParams, "\"comment\" must be one line of at most 200 characters");
    }
    entry.comment = comment;
  }
  return entry;
}

}  // namespace

void register_setup_methods(RpcDispatcher& dispatcher, Task& task,
                            const config::MachineConfig& config) {
  dispatcher.add(
      "tool.list", [&task](const json&) { return task.tool_list(); }, Access::read);
  dispatcher.add("tool.set", [&task, &config](const json& params) {
    const interp::ToolEntry entry = tool_from_params(object_params(params), task, config);
    task.set_tool(entry);
    return json{{"number", entry.number}};
  });
  dispatcher.add(
      "offsets.get", [&task](const json&) { return task.offsets(); }, Access::read);
  dispatcher.add("offsets.set", [&task, &config](const json& params) {
    const json& p = object_params(params);
    allow_only(p, {"system", "origin", "rotation"});
    if (!p.contains("system")) throw RpcError(kInvalidParams, "\"system\" is missing");
    const int system = coord_system(p["system"]);
    interp::Pose origin{};
    std::uint32_t axes = 0;
    if (p.contains("origin")) read_axes(p["origin"], "origin", config, origin, axes);
    std::optional<double> rotation;
    if (p.contains("rotation")) rotation = finite_number(p["rotation"], "rotation", -360, 360);
    if (axes == 0 && !rotation) {
      throw RpcError(kInvalidParams, "give \"origin\" axis values or a \"rotation\"");
    }
    task.set_offsets(system, origin, axes, rotation);
    return json{{"system", coord_system_name(system)}};
  });
}

}  // namespace cncd::daemon
