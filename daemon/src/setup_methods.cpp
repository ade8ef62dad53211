// tool.list, tool.set, offsets.get, offsets.set: parameter checks and the calls into Task.
#include "setup_methods.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "cncd/interp/stored_values.hpp"
#include "status_json.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {

// {"x": 1.5, "z": -2} for the machine's axes; sets the bits of the axes named in `mask`.
void read_axes(const json& value, const std::string& name, const config::MachineConfig& config,
               interp::Pose& pose, std::uint32_t& mask) {
  // The interpreter's bound on every stored offset and tool value.
  constexpr double kLimit = interp::kMaxStoredValue;
  for (const auto& [key, number] : value.items()) {
    const auto index = key.size() == 1 ? config::kAxisLetters.find(static_cast<char>(
                                             std::toupper(static_cast<unsigned char>(key[0]))))
                                       : std::string_view::npos;
    if (index == std::string_view::npos || !config.axes[index].present) {
      throw RpcError(kInvalidParams, "parameter " + quoted_text(name) + " names axis " +
                                         quoted_text(key) + ", which this machine lacks");
    }
    if (!number.is_number() || std::abs(number.get<double>()) > kLimit) {
      throw RpcError(kInvalidParams, "parameter " + quoted_text(name + "." + key) +
                                         " must be a number from -1000000000 to 1000000000");
    }
    pose[index] = number.get<double>();
    mask |= 1U << index;
  }
}

// "G54" .. "G59.3" or 1 .. 9.
int coord_system(const json& value) {
  if (value.is_number_integer()) {
    const auto index = value.get<std::int64_t>();
    if (index < 1 || index > 9) {
      throw RpcError(kInvalidParams,
                     "parameter \"system\" must be an integer from 1 to 9 (or "
                     "one of G54 .. G59.3), not " +
                         value.dump());
    }
    return static_cast<int>(index);
  }
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
  throw RpcError(kInvalidParams, "parameter \"system\" must be one of G54 .. G59.3 (or 1 .. 9)");
}

interp::ToolEntry tool_from_params(const json& p, const Task& task,
                                   const config::MachineConfig& config) {
  const int number = p["number"].get<int>();
  interp::ToolEntry entry;
  if (const auto existing = task.find_tool(number)) {
    entry = *existing;
  } else {
    entry.number = number;
    entry.pocket = number;
  }
  if (p.contains("pocket")) entry.pocket = p["pocket"].get<int>();
  if (p.contains("offset")) {
    std::uint32_t mask = 0;
    read_axes(p["offset"], "offset", config, entry.offset, mask);
  }
  if (p.contains("diameter")) entry.diameter = p["diameter"].get<double>();
  if (p.contains("front_angle")) entry.front_angle = p["front_angle"].get<double>();
  if (p.contains("back_angle")) entry.back_angle = p["back_angle"].get<double>();
  if (p.contains("orientation")) entry.orientation = p["orientation"].get<int>();
  if (p.contains("comment")) {
    const std::string comment = p["comment"].get<std::string>();
    if (comment.size() > 200 || comment.find_first_of("\r\n") != std::string::npos) {
      throw RpcError(kInvalidParams,
                     "parameter \"comment\" must be one line of at most 200 characters");
    }
    entry.comment = comment;
  }
  return entry;
}

}  // namespace

void register_setup_methods(RpcDispatcher& dispatcher, Task& task,
                            const config::MachineConfig& config) {
  dispatcher.add("tool.list",
                 [&task, &config](const json&) { return tool_list_json(task.tools(), config); });
  dispatcher.add("tool.set", [&task, &config](const json& params) {
    const interp::ToolEntry entry = tool_from_params(params, task, config);
    task.set_tool(entry);
    return json{{"number", entry.number}};
  });
  dispatcher.add("offsets.get",
                 [&task, &config](const json&) { return offsets_json(task.offsets(), config); });
  dispatcher.add("offsets.set", [&task, &config](const json& p) {
    const int system = coord_system(p["system"]);
    interp::Pose origin{};
    std::uint32_t axes = 0;
    if (p.contains("origin")) read_axes(p["origin"], "origin", config, origin, axes);
    std::optional<double> rotation;
    if (p.contains("rotation")) rotation = p["rotation"].get<double>();
    if (axes == 0 && !rotation) {
      throw RpcError(kInvalidParams, "give \"origin\" axis values or a \"rotation\"");
    }
    task.set_offsets(system, origin, axes, rotation);
    return json{{"system", coord_system_name(system)}};
  });
}

}  // namespace cncd::daemon
