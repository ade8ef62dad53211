// The table of G and M codes: every code the parser accepts, its modal group and whether it is
// supported. Codes are stored as ten times their number (G81 -> 810, G59.3 -> 593) so that the
// dotted codes fit an integer. Parser, modal-group checks and the executor all read this table.
#pragma once

#include <cstdint>

namespace cncd::interp {

// Modal groups as LinuxCNC numbers them (G: 0..15, M: 4..10).
enum class GGroup : std::int8_t {
  none = -1,
  non_modal,  // 0, then counting up
  motion,
  plane,
  distance,
  arc_distance,
  feed_mode,
  units,
  cutter_comp,
  tool_length,  // 8
  retract = 10,
  coord_system = 12,
  path_control,
  spindle_mode,
  lathe_diameter,  // 15
};
inline constexpr int kGGroups = 16;

enum class MGroup : std::int8_t {
  none = -1,
  stopping = 4,  // then counting up
  io,
  tool_change,
  spindle,
  coolant,
  overrides,
  user,  // 10
};
inline constexpr int kMGroups = 11;

struct CodeInfo {
  std::int8_t group = -1;  // GGroup or MGroup value; -1 = unknown code
  bool supported = false;  // false: parsed, then rejected with "not supported"
};

// `code` is ten times the G number; returns group -1 for unknown codes.
CodeInfo g_code_info(int code);
// `code` is the M number.
CodeInfo m_code_info(int code);

}  // namespace cncd::interp
