// One parsed line: its words, codes, comments, parameter assignments and O-word. A Block is
// reused from line to line so that parsing a simple line allocates nothing.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "codes.hpp"

namespace cncd::interp {

enum class OKind : std::uint8_t {
  none,
  sub,
  endsub,
  call,
  do_,
  while_,
  endwhile,
  if_,
  elseif,
  else_,
  endif,
  break_,
  continue_,
  return_,
  repeat,
  endrepeat,
};

struct Block {
  // Letter words other than G, M and N, indexed by letter - 'a'.
  std::array<double, 26> value{};
  std::array<int, 26> column{};
  std::uint32_t present = 0;

  // At most one G code per modal group; -1 = none.
  std::array<int, kGGroups> g{};
  std::array<int, kGGroups> g_column{};
  // At most one M code per modal group; -1 = none.
  std::array<int, kMGroups> m{};
  std::array<int, kMGroups> m_column{};
  int m_count = 0;

  // LinuxCNC's polar words: @ distance and ^ angle (degrees) in the XY plane.
  bool has_polar_distance = false;
  bool has_polar_angle = false;
  double polar_distance = 0;
  double polar_angle = 0;

  bool block_delete = false;
  bool has_line_number = false;
  double line_number = 0;

  // Comments in order; `comment_count` of them are valid (the strings keep their capacity).
  std::vector<std::string> comments;
  int comment_count = 0;

  OKind o_kind = OKind::none;
  std::string o_name;  // "100" or "<name>" lowercased, as written after O
  int o_column = 0;
  bool has_o_value = false;  // if/while/elseif/repeat/return condition or value
  double o_value = 0;
  std::vector<double> call_args;

  // Numeryx dialect. The drilling cycle word (ten times: 730, 740, 810 .. 860, or 800 for g80)
  // and the R, Z, Q and D written after it, which belong to the cycle, not to the NC addresses.
  int nx_cycle = -1;
  int nx_cycle_column = 0;
  std::array<double, 4> nx_cycle_value{};  // r z q d
  std::array<int, 4> nx_cycle_col{};
  std::uint8_t nx_cycle_present = 0;
  // g10: polar positioning (pole I J, angle P in degrees, radius R).
  bool nx_polar = false;
  int nx_polar_column = 0;
  // for #n=start to end [step s] / next [#n]
  enum class Loop : std::uint8_t { none, for_, next };
  Loop nx_loop = Loop::none;
  int nx_loop_var = 0;  // 0 = next without a variable
  double nx_loop_start = 0;
  double nx_loop_end = 0;
  double nx_loop_step = 1;
  int nx_loop_column = 0;

  static int nx_cycle_slot(char letter) {
    return letter == 'r' ? 0 : letter == 'z' ? 1 : letter == 'q' ? 2 : letter == 'd' ? 3 : -1;
  }
  bool has_cycle(char letter) const {
    const int slot = nx_cycle_slot(letter);
    return slot >= 0 && ((nx_cycle_present >> slot) & 1U) != 0;
  }
  double cycle_value(char letter) const {
    return nx_cycle_value[static_cast<std::size_t>(nx_cycle_slot(letter))];
  }
  int cycle_col(char letter) const {
    return nx_cycle_col[static_cast<std::size_t>(nx_cycle_slot(letter))];
  }

  struct NumberedAssignment {
    int number;
    double value;
    int column;  // of its '#'
  };
  std::vector<NumberedAssignment> numbered_assignments;
  std::vector<std::pair<std::string, double>> named_assignments;
  int named_assignment_count = 0;

  bool has(char letter) const { return (present >> (letter - 'a')) & 1U; }
  double get(char letter) const { return value[static_cast<std::size_t>(letter - 'a')]; }
  int col(char letter) const { return column[static_cast<std::size_t>(letter - 'a')]; }
  int g_code(GGroup group) const { return g[static_cast<std::size_t>(group)]; }
  int m_code(MGroup group) const { return m[static_cast<std::size_t>(group)]; }

  void clear() {
    present = 0;
    has_polar_distance = has_polar_angle = false;
    g.fill(-1);
    m.fill(-1);
    m_count = 0;
    block_delete = false;
    has_line_number = false;
    comment_count = 0;
    o_kind = OKind::none;
    o_name.clear();
    has_o_value = false;
    call_args.clear();
    numbered_assignments.clear();
    named_assignment_count = 0;
    nx_cycle = -1;
    nx_cycle_present = 0;
    nx_polar = false;
    nx_loop = Loop::none;
    nx_loop_var = 0;
    nx_loop_step = 1;
  }
};

}  // namespace cncd::interp
