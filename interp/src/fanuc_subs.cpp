// Fanuc-style subprograms as LinuxCNC 2.9 runs them: "M98 P100 L3" calls the subprogram that
// starts at a bare "O100" line three times; M99 ends it (and, in the main program, ends the
// program like M2). A subprogram shares #1-#30 with its caller: it takes no arguments.
#include <cctype>
#include <cmath>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

// The deepest nesting of subprogram calls LinuxCNC allows an M98.
constexpr std::size_t kMaxFanucLevels = 9;

// LinuxCNC reads M98 only as the first word of a line (after block delete and N): anywhere
// else it is an unknown M code.
bool m98_comes_first(const std::string& line) {
  std::string text;
  for (const char c : line) {
    if (c != ' ' && c != '\t')
      text.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  std::size_t i = 0;
  if (i < text.size() && text[i] == '/') ++i;
  if (i < text.size() && text[i] == 'n') {
    ++i;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'))
      ++i;
  }
  if (i >= text.size() || text[i] != 'm') return false;
  ++i;
  int number = 0;
  bool digits = false;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) && number < 1000) {
    number = number * 10 + (text[i++] - '0');
    digits = true;
  }
  return digits && number == 98;
}

// O0100 and O100 name the same subprogram.
std::string_view without_leading_zeros(std::string_view name) {
  while (name.size() > 1 && name[0] == '0')
    name.remove_prefix(1);
  return name;
}

double integer_word(double value) {
  if (value != std::nearbyint(value)) fail("Non integer value for integer");
  return value;
}

}  // namespace

bool Interpreter::Impl::handle_fanuc_codes() {
  const int code = block_.m_code(MGroup::stopping);
  if (code != 98 && code != 99) return false;
  if (dialect_ == Dialect::numeryx) {
    fail("M" + std::to_string(code) + " is not supported in the Numeryx dialect",
         block_.m_column[static_cast<std::size_t>(MGroup::stopping)]);
  }
  if (code == 98) {
    do_m98();
    return true;
  }
  if (calls_.empty()) return false;  // M99 in the main program ends it like M2
  do_m99();
  return true;
}

// The rest of the program file from here: the first line that names `name`, a bare O-word (a
// Fanuc subprogram) or an "O.. sub" (a subroutine that needs "O.. call").
bool Interpreter::Impl::find_fanuc_sub(const std::string& name) {
  const std::int64_t offset = source().tell();
  const int line_number = source().line_number();
  OKind kind = OKind::none;
  while (source().read_line(line_)) {
    if (at_closing_percent()) end_at_closing_percent(name, true, source().line_number());
    if (!scan_o_line(line_, o_scan_name_, kind) ||
        without_leading_zeros(o_scan_name_) != without_leading_zeros(name)) {
      continue;
    }
    if (kind == OKind::sub) fail("'O.... sub' subroutine must be called with 'O.... call'");
    if (kind != OKind::none) continue;
    SubInfo info{sources_.size() - 1, source().tell(), source().line_number(), true};
    info.fanuc = true;
    subs_[name] = info;
    source().seek(offset, line_number);
    return true;
  }
  source().seek(offset, line_number);
  return false;
}

void Interpreter::Impl::do_m98() {
  if (!m98_comes_first(line_)) fail("Unknown m code used: M98");
  if (!block_.has('p')) fail("Found 'm98' code with no P-word");
  const double p = integer_word(block_.get('p'));
  int count = 1;
  if (block_.has('l')) {
    const double l = block_.get('l');
    if (l < 0) fail("Negative l word used", block_.col('l'));
    count = to_int(integer_word(l));
  }
  // LinuxCNC skips whatever else the line says (G0 X1 on an M98 line never moves): refuse it.
  const std::uint32_t others = block_.present & ~((1U << ('p' - 'a')) | (1U << ('l' - 'a')));
  bool g_codes = false;
  for (const int g : block_.g)
    g_codes = g_codes || g >= 0;
  if (others != 0 || g_codes || block_.m_count > 1 || block_.has_polar_distance ||
      block_.has_polar_angle) {
    fail("An M98 line takes only P and L words: put the other words on a line of their own");
  }
  if (count == 0) return;
  const std::string name = std::to_string(static_cast<long long>(p));
  const SubInfo& sub = known_sub(name, true);
  if (!sub.fanuc) fail("'O.... sub' subroutine must be called with 'O.... call'");
  if (calls_.size() >= kMaxFanucLevels) fail("Too many subroutine levels");
  if (sub.source != sources_.size() - 1)
    fail("Subprogram " + o_label(name) + " is not reachable from here");
  CallFrame frame;
  frame.name = name;
  frame.source = sources_.size() - 1;
  frame.return_offset = source().tell();
  frame.return_line = source().line_number();
  frame.control_depth = control_.size();
  frame.nx_loop_depth = nx_loops_.size();
  frame.fanuc = true;
  frame.repeats_left = count - 1;
  frame.sub_offset = sub.offset;
  frame.sub_line_before = sub.line_before;
  calls_.push_back(frame);
  parameters_.push_scope();
  source().seek(frame.sub_offset, frame.sub_line_before);
}

void Interpreter::Impl::do_m99() {
  CallFrame& frame = calls_.back();
  if (!frame.fanuc)
    fail("'O.... endsub' or 'O.... return' must follow 'O.... sub' subroutine definition");
  // LinuxCNC stops here with an internal error ("Bug: Reached convert_stop() from M99 ...").
  if (block_has_other_words()) {
    fail(
        "An M99 that ends a subprogram must be alone on its line: put the other words on a line "
        "of their own");
  }
  if (frame.repeats_left > 0) {
    // Each pass is a call of its own: what its M70/M73 saved ends with it.
    auto_restore_modal_state();
    frame.saved_modal = SavedModalState{};
    --frame.repeats_left;
    control_.resize(frame.control_depth);
    loop_back(frame.sub_offset, frame.sub_line_before);
    return;
  }
  do_return(false, 0.0);
}

}  // namespace cncd::interp
