// Writing a LinuxCNC tool table (.tbl) back: one "T P [axes] D [I J Q] ;comment" line a tool.
#pragma once

#include <string>
#include <vector>

#include "cncd/interp/tool_entry.hpp"

namespace cncd::daemon {

// The table's text, tools in the order given. Offsets are written only where non-zero (Z
// always), as LinuxCNC writes them, with six decimals.
std::string format_tool_table(const std::vector<interp::ToolEntry>& tools);

}  // namespace cncd::daemon
