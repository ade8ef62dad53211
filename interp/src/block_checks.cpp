// Checks of a whole block before anything runs: unsupported codes, axis words without a user,
// words no code uses, negative words. LinuxCNC's wording throughout.
#include <cmath>
#include <cstdio>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

// "G41.1 is not supported"; `code` is ten times the number.
std::string not_supported(char letter, int code) {
  char text[48];
  if (code % 10 != 0) {
    std::snprintf(text, sizeof text, "%c%d.%d is not supported", letter, code / 10, code % 10);
  } else {
    std::snprintf(text, sizeof text, "%c%d is not supported", letter, code / 10);
  }
  return text;
}

}  // namespace

// G10, G28, G30, G52 and G92 take the line's axis words for themselves; so do G43.1 and G43.2 when
// no motion code shares its line (with one, both use them).
bool Interpreter::Impl::axes_belong_elsewhere() const {
  return axes_belong_to_non_modal() || ((block_.g_code(GGroup::tool_length) == 431 ||
                                         block_.g_code(GGroup::tool_length) == 432) &&
                                        block_.g_code(GGroup::motion) < 0);
}

bool Interpreter::Impl::axes_belong_to_non_modal() const {
  const int code = block_.g_code(GGroup::non_modal);
  return code == 100 || code == 280 || code == 300 || code == 520 || code == 920;
}

void Interpreter::Impl::check_supported_codes() const {
  const Block& b = block_;
  for (int group = 0; group < kGGroups; ++group) {
    const int code = b.g[static_cast<std::size_t>(group)];
    if (code >= 0 && !g_code_info(code).supported) {
      fail(not_supported('G', code), b.g_column[static_cast<std::size_t>(group)]);
    }
  }
  for (int group = 0; group < kMGroups; ++group) {
    const int code = b.m[static_cast<std::size_t>(group)];
    if (code >= 0 && !m_code_info(code).supported) {
      fail(not_supported('M', code * 10), b.m_column[static_cast<std::size_t>(group)]);
    }
  }
  check_modal_state_line();
}

void Interpreter::Impl::check_block() const {
  const Block& b = block_;
  check_supported_codes();
  const bool polar = b.has_polar_distance || b.has_polar_angle;
  if (polar && b.has('x')) fail("Cannot specify both polar coordinate and X word", b.col('x'));
  if (polar && b.has('y')) fail("Cannot specify both polar coordinate and Y word", b.col('y'));
  bool axis_words = polar;
  for (const char letter : kAxisLetters) {
    if (letter != '\0' && b.has(letter)) axis_words = true;
  }
  const int motion = b.g_code(GGroup::motion);
  const int motion_column = b.g_column[static_cast<std::size_t>(GGroup::motion)];
  if (axes_belong_to_non_modal() && motion >= 0 && motion != 800) {
    fail("Cannot use two g codes that both use axis values", b.g_column[0]);
  }
  if (motion == 800 && axis_words && !axes_belong_elsewhere()) {
    fail("Cannot use axis values with g80", motion_column);
  }
  // Only G0-G3 may stand without an axis word (a move to where the tool is), and G5.2, whose
  // first line may give only the weight of the start point or the order.
  if (motion >= 0 && motion != 800 && motion > 30 && motion != 52 && !is_g7x_code(motion) &&
      !axis_words) {
    fail("All axes missing with motion code", motion_column);
  }
  if (axis_words && motion < 0 && !axes_belong_elsewhere() &&
      (modal_.motion < 0 || modal_.motion == 800)) {
    fail("Cannot use axis values without a g code that uses them");
  }
  const int active_motion = motion_to_be();
  const bool cycle = active_motion == 730 || active_motion == 740 ||
                     (active_motion >= 810 && active_motion <= 890);
  if (cycle) {
    for (const char letter : {'a', 'b', 'c'}) {
      if (b.has(letter)) {
        char message[40];
        std::snprintf(message, sizeof message, "Cannot put an %c in canned cycle", letter);
        fail(message, b.col(letter));
      }
    }
  }
  check_word_users(active_motion);
  if (b.has('f') && b.get('f') < 0) fail("Negative f word used", b.col('f'));
  if (b.has('s') && b.get('s') < 0) fail("Negative spindle speed used", b.col('s'));
  if (b.has('t') && b.get('t') < 0) fail("Negative t word used", b.col('t'));
}

// Words that no code on the line (or the modal motion) uses are errors in LinuxCNC, checked in
// its order: D E H I J K L P Q R.
void Interpreter::Impl::check_word_users(int motion) const {
  const Block& b = block_;
  const int non_modal = b.g_code(GGroup::non_modal);
  const bool g10 = non_modal == 100;
  const bool arc = motion == 20 || motion == 30;
  const bool cycle = motion == 730 || motion == 740 || (motion >= 810 && motion <= 890);
  const int overrides = b.m_code(MGroup::overrides);
  const int io = b.m_code(MGroup::io);  // M62-M68
  const bool user_m = b.m_code(MGroup::user) >= 0;
  auto require = [&](char letter, bool used, const char* message) {
    if (b.has(letter) && !used) fail(message, b.col(letter));
  };
  const bool css = b.g_code(GGroup::spindle_mode) == 960;
  const bool orient = b.m_code(MGroup::spindle) == 19;
  const bool bezier = motion == 50 || motion == 51;  // G5, G5.1
  const bool synced = motion == 330 || motion == 331;
  const bool thread = motion == 760;
  const bool g70 = motion == 700;
  const bool roughing = is_g7x_code(motion) && !g70;  // G71, G72 and their .1 and .2
  require('d', css || b.g_code(GGroup::cutter_comp) > 400 || g70 || roughing,
          "D word with no G41, G41.1, G42, G42.1, G71, G71.1, G71.2 or G96 to use it");
  require('e', io >= 66 || thread || g70, "E word with no G70, G76, M66, M67 or M68 to use it");
  require('h',
          b.g_code(GGroup::tool_length) == 430 || b.g_code(GGroup::tool_length) == 432 || thread,
          "H word with no G43 or G76 to use it");
  require('i', arc || bezier || g10 || motion == 870 || motion == 331 || thread || roughing,
          "I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use it");
  require('j', arc || bezier || g10 || motion == 870 || thread,
          "J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it");
  require('k', arc || motion == 870 || synced || thread,
          "K word with no G2, G3, G33, G33.1, G76, or G87 to use it");
  require('l',
          g10 || cycle || thread || io == 66 || b.g_code(GGroup::cutter_comp) > 400 || motion == 52,
          "L word with no G10, cutter compensation, canned cycle, digital/analog input, M98 or "
          "NURBS code");
  const bool p_user = arc || motion == 50 || motion == 52 || g10 || non_modal == 40 ||
                      b.g_code(GGroup::path_control) == 640 || motion == 820 || motion == 860 ||
                      motion == 880 || motion == 890 || motion == 840 || motion == 740 ||
                      (overrides >= 50 && overrides <= 53) || (io >= 62 && io <= 66) || orient ||
                      user_m || thread || g70;
  require('p', p_user,
          "P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or M50 M51 M52 M53 M62 "
          "M63 M64 M65 M66 M98 or user M code to use it");
  if (orient && b.has('p')) {
    const double p = b.get('p');
    const double whole = std::round(p);
    if (std::fabs(whole - p) > 0.001) fail("P value not an integer with M19 G2 or G3", b.col('p'));
    if (whole < 0 || whole > 2) fail("P value must be 0,1,or 2 with M19", b.col('p'));
  }
  const bool q_user = motion == 50 || g10 || b.g_code(GGroup::path_control) == 640 ||
                      motion == 730 || motion == 830 || b.m_code(MGroup::tool_change) == 61 ||
                      io >= 66 || orient || user_m || thread || g70 || roughing;
  require('q', q_user,
          "Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or user M code that "
          "uses it");
  require('r', arc || cycle || g10 || orient || thread || roughing,
          "R word with no g code that uses it");
  if (orient && b.has('r') && (b.get('r') > 360.0 || b.get('r') < 0.0)) {
    fail("R value must be within 0..360 with M19", b.col('r'));
  }
  check_spindle_words(motion);
}

// The word checks of G96 and G33/G33.1 that close LinuxCNC's list, in both dialects.
void Interpreter::Impl::check_spindle_words(int motion) const {
  const Block& b = block_;
  const int css = b.g_code(GGroup::spindle_mode);
  if (css == 960 && !b.has('s')) {
    fail("S word missing with G96", b.g_column[static_cast<std::size_t>(GGroup::spindle_mode)]);
  }
  if (motion == 760) check_threading_words();
  if (motion == 330 || motion == 331) {
    if (!b.has('k')) fail("K word missing with g33/g33.1");
    if (b.has('f')) fail("F word used with a g33/g33.1", b.col('f'));
  }
}

// LinuxCNC's "motion to be": the block's motion code; else, when the block has axis words that
// no group 0 code (or G43.1) takes, the modal motion; else the modal arc for a block of only
// I, J or K words; else none (-1). The words of a block are checked against it.
int Interpreter::Impl::motion_to_be() const {
  const Block& b = block_;
  const int motion = b.g_code(GGroup::motion);
  if (motion >= 0) return motion;
  if (axes_belong_elsewhere()) return -1;
  bool axis_words = b.has_polar_distance || b.has_polar_angle;
  for (const char letter : kAxisLetters) {
    if (letter != '\0' && b.has(letter)) axis_words = true;
  }
  if (axis_words) return modal_.motion;
  const bool ijk = b.has('i') || b.has('j') || b.has('k');
  if (ijk && (modal_.motion == 20 || modal_.motion == 30)) return modal_.motion;
  return -1;
}

}  // namespace cncd::interp
