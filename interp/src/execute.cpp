// One block in LinuxCNC's order of execution: comment, feed mode, feed, speed, tool, spindle,
// coolant, overrides, dwell, plane, units, cutter compensation, tool length, coordinate system,
// path control, distance modes, retract mode, non-modal codes, motion, stop.
#include <cctype>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

bool starts_with_word(const std::string& text, const char* word, std::size_t& rest) {
  std::size_t i = 0;
  for (; word[i] != '\0'; ++i) {
    if (i >= text.size()) return false;
    if (std::tolower(static_cast<unsigned char>(text[i])) != word[i]) return false;
  }
  rest = i;
  return true;
}

}  // namespace

// G10, G28, G30, G52 and G92 take the line's axis words for themselves; so does G43.1 when
// no motion code shares its line (with one, both use them).
bool Interpreter::Impl::axes_belong_elsewhere() const {
  return axes_belong_to_non_modal() ||
         (block_.g_code(GGroup::tool_length) == 431 && block_.g_code(GGroup::motion) < 0);
}

bool Interpreter::Impl::axes_belong_to_non_modal() const {
  const int code = block_.g_code(GGroup::non_modal);
  return code == 100 || code == 280 || code == 300 || code == 520 || code == 920;
}

void Interpreter::Impl::check_block() const {
  const Block& b = block_;
  for (int group = 0; group < kGGroups; ++group) {
    const int code = b.g[static_cast<std::size_t>(group)];
    if (code >= 0 && !g_code_info(code).supported) {
      fail("G" + std::to_string(code / 10) +
               (code % 10 != 0 ? "." + std::to_string(code % 10) : "") + " is not supported",
           b.g_column[static_cast<std::size_t>(group)]);
    }
  }
  for (int group = 0; group < kMGroups; ++group) {
    const int code = b.m[static_cast<std::size_t>(group)];
    if (code >= 0 && !m_code_info(code).supported) {
      fail("M" + std::to_string(code) + " is not supported",
           b.m_column[static_cast<std::size_t>(group)]);
    }
  }
  bool axis_words = false;
  for (const char letter : kAxisLetters) {
    if (letter != '\0' && b.has(letter)) axis_words = true;
  }
  const int motion = b.g_code(GGroup::motion);
  if (axes_belong_to_non_modal() && motion >= 0 && motion != 800) {
    fail("Cannot use two g codes that both use axis values", b.g_column[0]);
  }
  if (motion == 800 && axis_words && !axes_belong_elsewhere()) {
    fail("Cannot use axis values with g80", b.g_column[static_cast<std::size_t>(GGroup::motion)]);
  }
  if (axis_words && motion < 0 && !axes_belong_elsewhere() &&
      (modal_.motion < 0 || modal_.motion == 800)) {
    fail("Cannot use axis values without a g code that uses them");
  }
  const int active_motion = motion >= 0 ? motion : modal_.motion;
  const bool cycle = active_motion == 730 || active_motion == 740 ||
                     (active_motion >= 810 && active_motion <= 890);
  if (cycle && !axes_belong_elsewhere()) {
    for (const char letter : {'a', 'b', 'c'}) {
      if (b.has(letter)) {
        fail(std::string("Cannot put an ") + letter + " in canned cycle", b.col(letter));
      }
    }
  }
  check_word_users(active_motion);
  if (b.has('e')) fail("E word with no G70, G76, M66, M67 or M68 to use it", b.col('e'));
  if (b.has('f') && b.get('f') < 0) fail("Negative f word used", b.col('f'));
  if (b.has('s') && b.get('s') < 0) fail("Negative spindle speed used", b.col('s'));
  if (b.has('t') && b.get('t') < 0) fail("Negative t word used", b.col('t'));
}

// Words that no code on the line (or the modal motion) uses are errors in LinuxCNC.
void Interpreter::Impl::check_word_users(int motion) const {
  const Block& b = block_;
  const int non_modal = b.g_code(GGroup::non_modal);
  const bool g10 = non_modal == 100;
  const bool arc = motion == 20 || motion == 30;
  const bool cycle = motion == 730 || motion == 740 || (motion >= 810 && motion <= 890);
  const int overrides = b.m_code(MGroup::overrides);
  auto require = [&](char letter, bool used, const char* message) {
    if (b.has(letter) && !used) fail(message, b.col(letter));
  };
  require('i', arc || g10 || motion == 870,
          "I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use it");
  require('j', arc || g10 || motion == 870,
          "J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it");
  require('k', arc || motion == 870, "K word with no G2, G3, G33, G33.1, G76, or G87 to use it");
  require('r', arc || cycle || g10, "R word with no g code that uses it");
  const bool p_user = arc || g10 || non_modal == 40 || b.g_code(GGroup::path_control) == 640 ||
                      motion == 820 || motion == 860 || motion == 880 || motion == 890 ||
                      motion == 840 || motion == 740 || (overrides >= 50 && overrides <= 53);
  require('p', p_user,
          "P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or M50 M51 M52 M53 M62 "
          "M63 M64 M65 M66 M98 or user M code to use it");
  const bool q_user = g10 || b.g_code(GGroup::path_control) == 640 || motion == 730 ||
                      motion == 830 || b.m_code(MGroup::tool_change) == 61;
  require('q', q_user,
          "Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or user M code that "
          "uses it");
  require('l', g10 || cycle,
          "L word with no G10, cutter compensation, canned cycle, digital/analog input, M98 or "
          "NURBS code");
  require('d', false, "D word with no G41, G41.1, G42, G42.1, G71, G71.1, G71.2 or G96 to use it");
  require('h', b.g_code(GGroup::tool_length) == 430, "H word with no G43 or G76 to use it");
}

void Interpreter::Impl::execute_block() {
  check_block();
  do_comment();
  do_feed_mode();
  do_tool_and_spindle();
  do_coolant_and_overrides();
  do_dwell();
  do_modes();
  do_non_modal();
  do_motion();
  do_stop();
}

void Interpreter::Impl::do_comment() {
  if (block_.comment_count == 0) return;
  // LinuxCNC acts on the last comment of a line only.
  const std::string& text = block_.comments[static_cast<std::size_t>(block_.comment_count - 1)];
  std::size_t rest = 0;
  if (starts_with_word(text, "msg,", rest)) {
    CanonCommand& command = make(CanonKind::message);
    command.text = text.substr(rest);
    emit(command);
    return;
  }
  emit_comment(text);
}

void Interpreter::Impl::do_feed_mode() {
  const int code = block_.g_code(GGroup::feed_mode);
  if (code >= 0) {
    if (code == 930) {
      emit_comment("interpreter: feed mode set to inverse time");
      emit_simple(CanonKind::set_feed_mode, 0);
      modal_.feed_mode = FeedMode::inverse_time;
      modal_.feed_rate = 0;
    } else if (code == 940) {
      emit_comment("interpreter: feed mode set to units per minute");
      emit_simple(CanonKind::set_feed_mode, 0);
      modal_.feed_mode = FeedMode::units_per_minute;
      modal_.feed_rate = 0;
      emit_simple(CanonKind::set_feed_rate, 0, 0.0);
    } else {
      emit_comment("interpreter: feed mode set to units per revolution");
      emit_simple(CanonKind::set_feed_mode, 1);
      modal_.feed_mode = FeedMode::units_per_rev;
      modal_.feed_rate = 0;
      emit_simple(CanonKind::set_feed_rate, 0, 0.0);
    }
  }
  if (block_.has('f')) {
    modal_.feed_rate = block_.get('f');
    if (modal_.feed_mode != FeedMode::inverse_time) {
      emit_simple(CanonKind::set_feed_rate, 0, modal_.feed_rate);
    }
  }
}

void Interpreter::Impl::do_tool_and_spindle() {
  if (block_.has('s')) {
    modal_.speed = block_.get('s');
    emit_simple(CanonKind::set_spindle_speed, 0, modal_.speed);
  }
  if (block_.has('t')) {
    const int tool = static_cast<int>(block_.get('t'));
    if (tool != 0 && tools_.find(tool) == nullptr && !options_.tool_table.empty()) {
      fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
           block_.col('t'));
    }
    tool_prepped_ = tool;
    emit_simple(CanonKind::select_tool, tool);
  }
  const int change = block_.m_code(MGroup::tool_change);
  if (change == 6) {
    const int tool = tool_prepped_ < 0 ? tool_in_spindle_ : tool_prepped_;
    emit_simple(CanonKind::start_change);
    emit_simple(CanonKind::stop_spindle_turning);
    emit_simple(CanonKind::change_tool, tool);
    tool_in_spindle_ = tool;
    modal_.spindle = SpindleDir::stopped;
  } else if (change == 61) {
    if (!block_.has('q') || block_.get('q') < 0) {
      fail("Need non-negative Q-word to specify tool number with M61", block_.m_column[6]);
    }
    const int tool = static_cast<int>(block_.get('q'));
    tool_in_spindle_ = tool;
    emit_simple(CanonKind::change_tool_number, tool);
  }
  switch (block_.m_code(MGroup::spindle)) {
    case 3:
      modal_.spindle = SpindleDir::clockwise;
      emit_simple(CanonKind::start_spindle_clockwise);
      break;
    case 4:
      modal_.spindle = SpindleDir::counterclockwise;
      emit_simple(CanonKind::start_spindle_counterclockwise);
      break;
    case 5:
      modal_.spindle = SpindleDir::stopped;
      emit_simple(CanonKind::stop_spindle_turning);
      break;
    default:
      break;
  }
}

void Interpreter::Impl::do_coolant_and_overrides() {
  switch (block_.m_code(MGroup::coolant)) {
    case 7:
      modal_.mist = true;
      emit_simple(CanonKind::mist_on);
      break;
    case 8:
      modal_.flood = true;
      emit_simple(CanonKind::flood_on);
      break;
    case 9:
      modal_.mist = modal_.flood = false;
      emit_simple(CanonKind::mist_off);
      emit_simple(CanonKind::flood_off);
      break;
    default:
      break;
  }
  const int code = block_.m_code(MGroup::overrides);
  if (code < 0) return;
  const bool has_p = block_.has('p');
  const bool on = !has_p || block_.get('p') != 0.0;
  switch (code) {
    case 48:
      modal_.feed_override = modal_.speed_override = true;
      emit_simple(CanonKind::set_feed_override_enable, 1);
      emit_simple(CanonKind::set_spindle_override_enable, 1);
      break;
    case 49:
      modal_.feed_override = modal_.speed_override = false;
      emit_simple(CanonKind::set_feed_override_enable, 0);
      emit_simple(CanonKind::set_spindle_override_enable, 0);
      break;
    case 50:
      modal_.feed_override = on;
      emit_simple(CanonKind::set_feed_override_enable, on ? 1 : 0);
      break;
    case 51:
      modal_.speed_override = on;
      emit_simple(CanonKind::set_spindle_override_enable, on ? 1 : 0);
      break;
    case 52:
      modal_.adaptive_feed = on;
      emit_simple(CanonKind::set_adaptive_feed_enable, on ? 1 : 0);
      break;
    default:
      modal_.feed_hold = on;
      emit_simple(CanonKind::set_feed_hold_enable, on ? 1 : 0);
      break;
  }
}

void Interpreter::Impl::do_dwell() {
  if (block_.g_code(GGroup::non_modal) != 40) return;
  if (!block_.has('p') || block_.get('p') < 0) {
    fail("Dwell time missing with g4", block_.g_column[0]);
  }
  emit_simple(CanonKind::dwell, 0, block_.get('p'));
}

void Interpreter::Impl::do_modes() {
  const int plane = block_.g_code(GGroup::plane);
  if (plane >= 0) {
    modal_.plane = plane == 170 ? Plane::xy : plane == 180 ? Plane::xz : Plane::yz;
    CanonCommand& command = make(CanonKind::select_plane);
    command.plane = modal_.plane;
    command.ivalue = static_cast<int>(modal_.plane);
    emit(command);
  }
  const int units = block_.g_code(GGroup::units);
  if (units >= 0) change_units(units == 200 ? Units::inches : Units::mm);
  const int comp = block_.g_code(GGroup::cutter_comp);
  if (comp == 400) emit_comment("interpreter: cutter radius compensation off");
  const int length = block_.g_code(GGroup::tool_length);
  if (length >= 0) apply_tool_length(length);
  const int system = block_.g_code(GGroup::coord_system);
  if (system >= 0) {
    static constexpr int kSystems[] = {540, 550, 560, 570, 580, 590, 591, 592, 593};
    for (int i = 0; i < 9; ++i) {
      if (kSystems[i] == system) select_coord_system(i + 1);
    }
  }
  const int path = block_.g_code(GGroup::path_control);
  if (path >= 0) {
    CanonCommand& command = make(CanonKind::set_motion_control_mode);
    if (path == 610) {
      modal_.control = MotionMode::exact_path;
    } else if (path == 611) {
      modal_.control = MotionMode::exact_stop;
    } else {
      modal_.control = MotionMode::continuous;
      modal_.tolerance = block_.has('p') ? block_.get('p') : 0.0;
      modal_.naive_tolerance = block_.has('q') ? block_.get('q') : modal_.tolerance;
    }
    command.ivalue = static_cast<int>(modal_.control);
    command.value = modal_.tolerance;
    emit(command);
    if (path == 640) emit_simple(CanonKind::set_naivecam_tolerance, 0, modal_.naive_tolerance);
  }
  const int distance = block_.g_code(GGroup::distance);
  if (distance == 900 && modal_.incremental) {
    modal_.incremental = false;
    emit_comment("interpreter: distance mode changed to absolute");
  } else if (distance == 910 && !modal_.incremental) {
    modal_.incremental = true;
    emit_comment("interpreter: distance mode changed to incremental");
  }
  const int arc_distance = block_.g_code(GGroup::arc_distance);
  if (arc_distance == 901 && modal_.arc_incremental) {
    modal_.arc_incremental = false;
    emit_comment("interpreter: IJK distance mode changed to absolute");
  } else if (arc_distance == 911 && !modal_.arc_incremental) {
    modal_.arc_incremental = true;
    emit_comment("interpreter: IJK distance mode changed to incremental");
  }
  const int retract = block_.g_code(GGroup::retract);
  if (retract == 980) {
    modal_.retract_r_plane = false;
    emit_comment("interpreter: retract mode set to old_z");
  } else if (retract == 990) {
    modal_.retract_r_plane = true;
    emit_comment("interpreter: retract mode set to r_plane");
  }
}

void Interpreter::Impl::do_non_modal() {
  switch (block_.g_code(GGroup::non_modal)) {
    case 100:
      do_g10();
      break;
    case 280:
    case 281:
    case 300:
    case 301:
      do_home(block_.g_code(GGroup::non_modal));
      break;
    case 520:
    case 920:
    case 921:
    case 922:
    case 923:
      do_g92(block_.g_code(GGroup::non_modal));
      break;
    default:
      break;
  }
}

bool Interpreter::Impl::do_stop() {
  switch (block_.m_code(MGroup::stopping)) {
    case 0:
      emit_simple(CanonKind::program_stop);
      return true;
    case 1:
      emit_simple(CanonKind::optional_program_stop);
      return true;
    case 60:
      emit_simple(CanonKind::pallet_shuttle);
      emit_simple(CanonKind::program_stop);
      return true;
    case 2:
    case 30:
      program_end_reset();
      ended_ = true;
      return true;
    default:
      return false;
  }
}

// What M2/M30 reset, in the order LinuxCNC emits it.
void Interpreter::Impl::program_end_reset() {
  select_coord_system_quiet(1);
  emit_g5x();
  rotation_deg_ = 0;
  emit_simple(CanonKind::set_xy_rotation, 0, 0.0);
  if (modal_.plane != Plane::xy) {
    modal_.plane = Plane::xy;
    CanonCommand& command = make(CanonKind::select_plane);
    command.plane = Plane::xy;
    command.ivalue = static_cast<int>(Plane::xy);
    emit(command);
  }
  modal_.incremental = false;
  modal_.feed_mode = FeedMode::units_per_minute;
  emit_simple(CanonKind::set_feed_mode, 0);
  modal_.feed_rate = 0;
  emit_simple(CanonKind::set_feed_rate, 0, 0.0);
  if (!modal_.feed_override) {
    // LinuxCNC re-enables only the feed override here; the speed override stays as it was.
    modal_.feed_override = true;
    emit_simple(CanonKind::set_feed_override_enable, 1);
  }
  modal_.spindle = SpindleDir::stopped;
  emit_simple(CanonKind::stop_spindle_turning);
  emit_simple(CanonKind::set_spindle_mode, 0, 0.0);
  if (modal_.mist) emit_simple(CanonKind::mist_off);
  if (modal_.flood) emit_simple(CanonKind::flood_off);
  modal_.mist = modal_.flood = false;
  modal_.motion = 10;
  if (block_.m_code(MGroup::stopping) == 30) emit_simple(CanonKind::pallet_shuttle);
  emit_simple(CanonKind::program_end);
}

}  // namespace cncd::interp
