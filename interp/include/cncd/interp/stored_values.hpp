// The bound on every value that outlives a block: coordinate system origins and rotations,
// G92 offsets, G28/G30 points (the persistent parameters #5161-#5390, as the parameter file
// holds them), tool table data and the tool length offset in force.
#pragma once

#include <cmath>
#include <optional>
#include <string>

#include "cncd/interp/tool_entry.hpp"

namespace cncd::interp {

// Machine units (or degrees, or the tool table's units). A kilometre is the largest travel of
// any machine; 1e9 leaves room for any unit and keeps sums of a few such values exact to far
// below a micrometre, where 1e300 offsets would swallow the move or overflow to infinity.
inline constexpr double kMaxStoredValue = 1e9;

// Finite and at most kMaxStoredValue in size (a NaN is not).
inline bool storable(double value) {
  return std::fabs(value) <= kMaxStoredValue;
}

// "<what> = <value> is out of range: offsets, origins, stored positions and tool data must be
// finite and at most 1e9 in size".
std::string out_of_range_message(const std::string& what, double value);

// Why `entry` cannot be stored (its first offset, diameter or angle that is not storable), or
// nullopt.
std::optional<std::string> tool_entry_problem(const ToolEntry& entry);

}  // namespace cncd::interp
