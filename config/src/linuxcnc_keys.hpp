// Keys that LinuxCNC, its user interfaces and its configuration wizards read in the sections
// cncd reads too, but that cncd does not interpret (not installed). Such a key is never
// reported as unknown.
#pragma once

#include <string_view>
#include <vector>

namespace cncd::config {

// The keys of a section written as the key table writes it ("TRAJ", "JOINT_n", "AXIS_L").
std::vector<std::string_view> linuxcnc_keys(std::string_view section_pattern);

}  // namespace cncd::config
