// The Numeryx dialect's blocks (application note An-101): drilling cycles whose heights are
// R1 = R + clearance and the initial Z (Zi), cycle variables written after the cycle word, the
// cycle's own g90/g91, g10 polar positioning and for/next loops. Everything else runs through
// the LinuxCNC core unchanged.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

std::string g_name(int code) {
  return "g" + std::to_string(code / 10);
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", value);
  return text;
}

// Loop ends compare with a little room, so that a step such as 0.1 reaches an end of 1.
double loop_slack(double end) {
  return 1e-9 * std::max(1.0, std::fabs(end));
}

std::string no_progress(int var, double step, double value, double end) {
  char text[200];
  std::snprintf(text, sizeof text,
                "Step %.17g does not change #%d (%.17g): the for loop would never reach %.17g",
                step, var, value, end);
  return text;
}

}  // namespace

void Interpreter::Impl::check_numeryx_block() const {
  const Block& b = block_;
  check_supported_codes();
  if (b.nx_polar) {
    for (const char letter : {'x', 'y'}) {
      if (b.has(letter)) {
        fail(std::string("Cannot use ") + letter +
                 " with g10: the polar position (i, j, p, r) gives x and y",
             b.col(letter));
      }
    }
    if (b.has_polar_distance || b.has_polar_angle) {
      fail("Cannot use @ or ^ with g10", b.nx_polar_column);
    }
  }
  const bool cycle_word = b.nx_cycle > 0 && b.nx_cycle != 800;
  const bool drilling = cycle_word || (nx_.cycle != 0 && b.nx_cycle != 800);
  bool axis_words = b.nx_polar || b.has_polar_distance || b.has_polar_angle;
  for (const char letter : kAxisLetters) {
    if (letter != '\0' && b.has(letter)) axis_words = true;
  }
  const int motion = b.g_code(GGroup::motion);
  const int active_motion = motion >= 0 ? motion : modal_.motion;
  if (motion >= 0 && motion > 30 && !axis_words) {
    fail("All axes missing with motion code", b.g_column[static_cast<std::size_t>(GGroup::motion)]);
  }
  if (axis_words && !drilling && !b.nx_polar && active_motion < 0 && !axes_belong_elsewhere()) {
    fail("Cannot use axis values without a g code that uses them");
  }
  if (drilling) {
    for (const char letter : {'a', 'b', 'c'}) {
      if (b.has(letter)) {
        fail(std::string("Cannot put an ") + letter + " in a drilling cycle", b.col(letter));
      }
    }
  }
  const bool arc = !drilling && (active_motion == 20 || active_motion == 30);
  const int synced = drilling ? -1 : motion_to_be();
  const int non_modal = b.g_code(GGroup::non_modal);
  const int overrides = b.m_code(MGroup::overrides);
  const int io = b.m_code(MGroup::io);
  const bool user_m = b.m_code(MGroup::user) >= 0;
  auto require = [&](char letter, bool used, const std::string& message) {
    if (b.has(letter) && !used) fail(message, b.col(letter));
  };
  const std::string cycle_hint =
      " (a drilling cycle's R, Z, Q and D are written after the "
      "cycle word: g81 r.. z..)";
  require('d', b.g_code(GGroup::spindle_mode) == 960,
          "D word with no drilling cycle or G96 to use it" + cycle_hint);
  require('e', io >= 66, "E word with no M66, M67 or M68 to use it");
  require('h', b.g_code(GGroup::tool_length) == 430, "H word with no G43 to use it");
  require('i', arc || b.nx_polar || synced == 331, "I word with no g2, g3, g10 or g33.1 to use it");
  require('j', arc || b.nx_polar, "J word with no g2, g3 or g10 to use it");
  require('k', arc || synced == 330 || synced == 331,
          "K word with no g2, g3, g33 or g33.1 to use it");
  require('l', io == 66, "L word with no M66 to use it");
  require('p',
          arc || b.nx_polar || non_modal == 40 || b.g_code(GGroup::path_control) == 640 ||
              (overrides >= 50 && overrides <= 53) || (io >= 62 && io <= 66) || user_m,
          "P word with no g2, g3, g4, g10, g64, M50-M53, M62-M66 or user M code to use it");
  require('q',
          b.g_code(GGroup::path_control) == 640 || b.m_code(MGroup::tool_change) == 61 ||
              io >= 66 || user_m,
          "Q word with no g64, M61, M66-M68 or user M code to use it" + cycle_hint);
  require('r', arc || b.nx_polar, "R word with no g2, g3 or g10 to use it" + cycle_hint);
  check_spindle_words(synced);
  if (b.has('f') && b.get('f') < 0) fail("Negative f word used", b.col('f'));
  if (b.has('s') && b.get('s') < 0) fail("Negative spindle speed used", b.col('s'));
  if (b.has('t') && b.get('t') < 0) fail("Negative t word used", b.col('t'));
  if (b.has_cycle('d') && b.cycle_value('d') < 0) {
    fail("Negative D (dwell) in a drilling cycle", b.cycle_col('d'));
  }
}

// G90/G91 belong to the drilling cycle while one is active (or after the cycle word that starts
// one), and then leave the X/Y distance mode alone; units may not change under a cycle.
void Interpreter::Impl::numeryx_modes() {
  const int word = block_.nx_cycle;
  const bool cycle_word = word > 0 && word != 800;
  nx_cycle_distance_ = -1;
  const auto distance_group = static_cast<std::size_t>(GGroup::distance);
  const int distance = block_.g[distance_group];
  if (distance >= 0) {
    const bool after_word = cycle_word && block_.g_column[distance_group] > block_.nx_cycle_column;
    const bool under_cycle = nx_.cycle != 0 && word != 800;
    if (after_word || under_cycle) {
      nx_cycle_distance_ = distance;
      block_.g[distance_group] = -1;
    }
  }
  const auto units_group = static_cast<std::size_t>(GGroup::units);
  const int units = block_.g[units_group];
  if (units >= 0) {
    const Units wanted = units == 200 ? Units::inches : Units::mm;
    const bool after_word = cycle_word && block_.g_column[units_group] > block_.nx_cycle_column;
    if (wanted != modal_.units && ((nx_.cycle != 0 && word != 800) || after_word)) {
      fail(
          "Cannot switch between inch and metric while a drilling cycle is active: its R, Z "
          "and Q keep the units they were given (g80 first)",
          block_.g_column[units_group]);
    }
  }
  do_modes();
}

void Interpreter::Impl::set_zi() {
  nx_.has_zi = true;
  nx_.zi = pos_[kZ];
  nx_.zi_units = modal_.units;
}

void Interpreter::Impl::numeryx_motion() {
  const int word = block_.nx_cycle;
  const bool cycle_word = word > 0 && word != 800;
  previous_motion_ = modal_.motion;
  if (word == 800) {
    // G80 ends the cycle and cancels G99: the next cycle starts with G98.
    nx_.cycle = 0;
    if (modal_.retract_r_plane) {
      modal_.retract_r_plane = false;
      emit_comment("interpreter: retract mode set to old_z");
    }
  }
  if (block_.nx_polar) {
    if (block_.has('i')) nx_.pole_i = block_.get('i');
    if (block_.has('j')) nx_.pole_j = block_.get('j');
    if (block_.has('r')) nx_.radius = block_.get('r');
    if (block_.has('p')) nx_.angle = block_.get('p');
    // g10 positions like g0, in polar coordinates.
    const auto motion_group = static_cast<std::size_t>(GGroup::motion);
    if (block_.g[motion_group] < 0) block_.g[motion_group] = 0;
  }
  bool axis_words = block_.nx_polar || block_.has_polar_distance || block_.has_polar_angle;
  for (int axis = 0; axis < kAxes; ++axis)
    axis_words |= block_.has(kAxisLetters[axis]);
  const bool drilling = cycle_word || nx_.cycle != 0;
  if (!drilling || axes_belong_elsewhere()) {
    do_motion();
    if (axis_words && block_.has('z') && !axes_belong_elsewhere()) set_zi();
    return;
  }
  const int explicit_code = block_.g_code(GGroup::motion);
  if (explicit_code >= 0) modal_.motion = explicit_code;
  if (axis_words) {
    // The positioning block: where the hole is, and (with Z) the new initial Z.
    const int code = modal_.motion < 0 ? 0 : modal_.motion;
    if (code != 0 && code != 10) {
      fail("Cannot position for a drilling cycle with " + g_name(code) + ": use g (g0) or g1",
           explicit_code >= 0 ? block_.g_column[static_cast<std::size_t>(GGroup::motion)] : 0);
    }
    if (code == 10 && modal_.feed_rate == 0.0) fail("Cannot do g1 with zero feed rate");
    straight(code == 0 ? StraightKind::traverse : StraightKind::feed, target_from_words());
    if (block_.has('z')) set_zi();
  }
  if (cycle_word) define_numeryx_cycle(word);
  if (nx_cycle_distance_ >= 0) nx_.incremental = nx_cycle_distance_ == 910;
  if (axis_words || cycle_word) numeryx_drill();
}

// The cycle word: a fresh cycle (after g80) starts from the defaults (D 0, g90 for R and Z);
// writing it again while a cycle is active changes the variables given and keeps the rest.
void Interpreter::Impl::define_numeryx_cycle(int code) {
  if (nx_.cycle == 0) {
    nx_.r = nx_.z = nx_.q = nx_.d = 0;
    nx_.has_r = nx_.has_z = nx_.has_q = false;
    nx_.incremental = false;
    if (!nx_.has_zi) set_zi();
  }
  nx_.cycle = code;
  if (block_.has_cycle('r')) {
    nx_.r = block_.cycle_value('r');
    nx_.has_r = true;
  }
  if (block_.has_cycle('z')) {
    nx_.z = block_.cycle_value('z');
    nx_.has_z = true;
  }
  if (block_.has_cycle('q')) {
    nx_.q = block_.cycle_value('q');
    nx_.has_q = true;
  }
  if (block_.has_cycle('d')) nx_.d = block_.cycle_value('d');
  const int column = block_.nx_cycle_column;
  if (!nx_.has_r) {
    fail(g_name(code) + " needs R, the Z where drilling begins (r after " + g_name(code) + ")",
         column);
  }
  if (!nx_.has_z) {
    fail(g_name(code) + " needs Z, the bottom of the hole (z after " + g_name(code) + ")", column);
  }
  if ((code == 730 || code == 830) && (!nx_.has_q || nx_.q <= 0)) {
    fail(
        g_name(code) + " needs a positive Q, the depth of each peck (q after " + g_name(code) + ")",
        block_.has_cycle('q') ? block_.cycle_col('q') : column);
  }
}

// One hole where the tool stands: rapid to R1 = R + clearance, the cycle's moves down to the
// bottom, and back to Zi (G98) or R1 (G99).
void Interpreter::Impl::numeryx_drill() {
  const int code = nx_.cycle;
  if (modal_.feed_mode == FeedMode::inverse_time) {
    fail("Cannot use inverse time feed with drilling cycles");
  }
  if (modal_.feed_rate == 0.0) fail("Cannot feed with zero feed rate");
  if (!nx_.has_zi) set_zi();
  const double zi = nx_.zi * unit_factor(nx_.zi_units, modal_.units);
  const double clearance = options_.numeryx_clearance
                               ? to_program_units(*options_.numeryx_clearance)
                               : (modal_.units == Units::inches ? 0.04 : 1.0);
  const double r = nx_.incremental ? zi + nx_.r : nx_.r;
  const double bottom = nx_.incremental ? r + nx_.z : nx_.z;
  if (bottom >= r) {
    fail("The bottom of the hole (Z " + number(bottom) + ") is not below R (Z " + number(r) + ")" +
         (nx_.incremental ? ": with g91, R is from Zi and Z from R, both negative" : ""));
  }
  CycleGeometry g;
  g.r = r + clearance;
  g.bottom = bottom;
  g.clear = modal_.retract_r_plane ? g.r : std::max(zi, g.r);
  g.position_first = false;
  g.peck_top = r;
  g.dwell = nx_.d;
  cycle_.q = nx_.q;
  cycle_.p = nx_.d;
  const bool switch_mode = modal_.control != MotionMode::exact_path;
  if (switch_mode) emit(SetMotionControlMode{MotionMode::exact_path, 0.0});
  double current = pos_[kZ];
  cycle_body(code, g, pos_[kX], pos_[kY], current);
  if (switch_mode) {
    emit(SetMotionControlMode{modal_.control, modal_.tolerance});
    emit(SetNaivecamTolerance{modal_.naive_tolerance});
  }
}

bool Interpreter::Impl::handle_numeryx_loop() {
  const Block& b = block_;
  const int column = b.nx_loop_column;
  if (b.nx_loop == Block::Loop::for_) {
    bool other = b.present != 0 || b.m_count > 0 || b.nx_cycle >= 0 || b.nx_polar ||
                 b.has_polar_distance || b.has_polar_angle;
    for (const int code : b.g)
      other = other || code >= 0;
    if (other) fail("Nothing but the loop may stand on a for line", column);
    parameters_.check(b.nx_loop_var, b.nx_loop_start, column);
    parameters_.set(b.nx_loop_var, b.nx_loop_start, column);
    const double step = b.nx_loop_step;
    const double slack = loop_slack(b.nx_loop_end);
    const bool runs = step > 0 ? b.nx_loop_start <= b.nx_loop_end + slack
                               : b.nx_loop_start >= b.nx_loop_end - slack;
    // A step lost in the rounding of a large value leaves the variable where it is: the loop
    // would run for ever.
    if (runs && b.nx_loop_start + step == b.nx_loop_start)
      fail(no_progress(b.nx_loop_var, step, b.nx_loop_start, b.nx_loop_end), column);
    nx_loops_.push_back(ForFrame{b.nx_loop_var, b.nx_loop_end, step, source().tell(),
                                 source().line_number(), current_line_, !runs});
    if (!runs) skip_numeryx_loop();
    return true;
  }
  if (nx_loops_.empty()) fail("next without a for loop", column);
  const ForFrame& top = nx_loops_.back();
  // The caller's loop cannot be closed from a subroutine: its body is in the caller.
  if (!calls_.empty() && nx_loops_.size() <= calls_.back().nx_loop_depth) {
    fail("next without for in subroutine " + o_label(calls_.back().name) + ": the for #" +
             std::to_string(top.var) + " of line " + std::to_string(top.for_line) +
             " belongs to its caller",
         column);
  }
  if (b.nx_loop_var != 0 && b.nx_loop_var != top.var) {
    fail("next #" + std::to_string(b.nx_loop_var) + " does not close the loop of for #" +
             std::to_string(top.var) + " (line " + std::to_string(top.for_line) + ")",
         column);
  }
  if (!top.skipped) {
    const double value = parameters_.get(top.var) + top.step;
    const double slack = loop_slack(top.end);
    if (top.step > 0 ? value <= top.end + slack : value >= top.end - slack) {
      // The body may have set the variable where the step no longer changes it.
      if (value == parameters_.get(top.var))
        fail(no_progress(top.var, top.step, value, top.end), column);
      parameters_.set(top.var, value, column);
      loop_back(top.offset, top.line_before);
      return true;
    }
  }
  nx_loops_.pop_back();
  return false;  // the rest of the next line (e.g. g80) runs once, after the loop
}

// A loop that runs no pass: on to its own next line (loops inside it are skipped with it).
void Interpreter::Impl::skip_numeryx_loop() {
  LineSource& src = source();
  const int for_line = current_line_;
  int depth = 1;
  std::string line;
  for (;;) {
    const std::int64_t offset = src.tell();
    const int before = src.line_number();
    if (!src.read_line(line)) {
      current_line_ = for_line;
      fail("for loop without next");
    }
    std::string text;
    for (const char c : line) {
      if (c == ' ' || c == '\t') continue;
      if (c == '(' || c == ';') break;
      text.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    }
    std::size_t at = 0;
    if (!text.empty() && text[0] == '/') ++at;
    if (at + 1 < text.size() && text[at] == 'n' &&
        std::isdigit(static_cast<unsigned char>(text[at + 1]))) {
      ++at;
      while (at < text.size() &&
             (std::isdigit(static_cast<unsigned char>(text[at])) || text[at] == '.'))
        ++at;
    }
    const std::string_view rest = std::string_view(text).substr(at);
    if (rest.starts_with("for#")) ++depth;
    if (rest.starts_with("next") && --depth == 0) {
      src.seek(offset, before);
      return;
    }
  }
}

}  // namespace cncd::interp
