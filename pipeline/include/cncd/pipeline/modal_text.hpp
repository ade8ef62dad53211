// The interpreter's modal state as LinuxCNC's displays name it, and run from line as
// cncd-check --from-line prints it.
#pragma once

#include <string>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::pipeline {

// 593 -> "G59.3": LinuxCNC's codes are ten times the number.
std::string code_name(char letter, int code);
// The active codes in LinuxCNC's modal-group order, without the line number and empty groups.
std::vector<std::string> active_g_codes(const interp::InterpState& state);
std::vector<std::string> active_m_codes(const interp::InterpState& state);

// What a run from a line rebuilds (the state the lines before it leave) and does before the
// line's own moves: the tool, the spindle and coolant, the way to the line's start.
struct FromLineReport {
  int line = 0;
  bool reached = false;  // the program reads the line (it does not end before it)
  interp::InterpState state;
  std::vector<motion::Move> lead_in;  // machine coordinates and units
};

// One line per item: the modal codes, F, S and tool, the offsets, then the moves and actions
// in order. `inch`: machine units are inches.
std::string describe_from_line(const FromLineReport& report, bool inch);

}  // namespace cncd::pipeline
