#include "tool_file.hpp"

#include <spdlog/fmt/fmt.h>

namespace cncd::daemon {

std::string format_tool_table(const std::vector<interp::ToolEntry>& tools) {
  static constexpr const char* kAxes = "XYZABCUVW";
  std::string out;
  for (const auto& tool : tools) {
    out += fmt::format("T{} P{}", tool.number, tool.pocket);
    for (std::size_t axis = 0; axis < tool.offset.size(); ++axis) {
      if (tool.offset[axis] != 0.0 || kAxes[axis] == 'Z')
        out += fmt::format(" {}{:+f}", kAxes[axis], tool.offset[axis]);
    }
    out += fmt::format(" D{:f}", tool.diameter);
    if (tool.front_angle != 0.0) out += fmt::format(" I{:+f}", tool.front_angle);
    if (tool.back_angle != 0.0) out += fmt::format(" J{:+f}", tool.back_angle);
    if (tool.orientation != 0) out += fmt::format(" Q{}", tool.orientation);
    out += " ;" + tool.comment + "\n";
  }
  return out;
}

}  // namespace cncd::daemon
