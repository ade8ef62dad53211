#include "cncd/interp/stored_values.hpp"

#include <cstdio>

namespace cncd::interp {

std::string out_of_range_message(const std::string& what, double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.10g", value);
  return what + " = " + text +
         " is out of range: offsets, origins, stored positions and tool data must be finite "
         "and at most 1e9 in size";
}

std::optional<std::string> tool_entry_problem(const ToolEntry& entry) {
  const std::string tool = "Tool " + std::to_string(entry.number);
  static constexpr const char* kLetters = "XYZABCUVW";
  for (std::size_t axis = 0; axis < entry.offset.size(); ++axis) {
    if (!storable(entry.offset[axis])) {
      return out_of_range_message(tool + " " + kLetters[axis] + " offset", entry.offset[axis]);
    }
  }
  if (!storable(entry.diameter)) return out_of_range_message(tool + " diameter", entry.diameter);
  if (!storable(entry.front_angle))
    return out_of_range_message(tool + " front angle", entry.front_angle);
  if (!storable(entry.back_angle))
    return out_of_range_message(tool + " back angle", entry.back_angle);
  return std::nullopt;
}

}  // namespace cncd::interp
