// One block in LinuxCNC's order of execution: comment, feed mode, feed, speed, tool, I/O
// (M62-M68), tool change, spindle, coolant, overrides, user M code, dwell, plane, units, cutter
// compensation, tool length, coordinate system, path control, distance modes, retract mode,
// non-modal codes, motion, stop.
#include <cmath>

#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

namespace {

// G90/G91 (`absolute_code` 900) or G90.1/G91.1 (901): sets `incremental` and returns the
// comment LinuxCNC makes of a change; "" when the block keeps the mode in force.
std::string distance_mode_change(int code, int absolute_code, bool& incremental,
                                 std::string_view what) {
  const bool to_incremental = code == absolute_code + 10;
  if ((code != absolute_code && !to_incremental) || incremental == to_incremental) return "";
  incremental = to_incremental;
  return "interpreter: " + std::string(what) + " mode changed to " +
         (to_incremental ? "incremental" : "absolute");
}

}  // namespace

// The Numeryx dialect checks its own codes and has its own modes and motion; the rest of the
// order is LinuxCNC's.
void Interpreter::Impl::execute_block() {
  const bool numeryx = dialect_ == Dialect::numeryx;
  if (numeryx) {
    check_numeryx_block();
  } else {
    check_block();
    halve_diameter_word();
  }
  do_comment();
  do_spindle_mode();
  do_feed_mode();
  do_tool_and_spindle();
  do_coolant_and_overrides();
  do_user_m_code();
  do_dwell();
  if (numeryx) {
    numeryx_modes();
  } else {
    do_modes();
  }
  do_non_modal();
  if (numeryx) {
    numeryx_motion();
  } else {
    do_motion();
    // G5.3 ends the G5.2 motion mode unless its line starts another curve.
    if (block_.g_code(GGroup::non_modal) == 53 && block_.g_code(GGroup::motion) < 0) {
      modal_.motion = 800;
    }
  }
  do_stop();
}

// Under G7 (in force or given on the line) every X word is a diameter: the position, G92, G10
// and G28/G30's X alike are half of it. I and R stay radii.
void Interpreter::Impl::halve_diameter_word() {
  const int code = block_.g_code(GGroup::lathe_diameter);
  const bool diameter = code < 0 ? modal_.diameter_mode : code == 70;
  if (diameter && block_.has('x')) block_.value[static_cast<std::size_t>('x' - 'a')] /= 2;
}

// G7 or G8: LinuxCNC notes a change of mode, not a repeat.
void Interpreter::Impl::set_diameter_mode(bool diameter) {
  if (diameter == modal_.diameter_mode) return;
  modal_.diameter_mode = diameter;
  emit_comment(diameter ? "interpreter: Lathe diameter mode changed to diameter"
                        : "interpreter: Lathe diameter mode changed to radius");
}

// G96 D.. S.. (constant surface speed, D the highest rpm) and G97, before the feed mode and
// the speed as in LinuxCNC: SET_SPINDLE_MODE(max rpm), 0 for G97; without D, 1e30.
void Interpreter::Impl::do_spindle_mode() {
  const int code = block_.g_code(GGroup::spindle_mode);
  if (code < 0) return;
  modal_.css = code == 960;
  modal_.css_max_rpm = 0;
  if (modal_.css) modal_.css_max_rpm = block_.has('d') ? std::fabs(block_.get('d')) : 1e30;
  emit(SetSpindleMode{modal_.css_max_rpm});
}

void Interpreter::Impl::do_feed_mode() {
  const int code = block_.g_code(GGroup::feed_mode);
  if (code >= 0) {
    set_feed_mode(code == 930   ? FeedMode::inverse_time
                  : code == 940 ? FeedMode::units_per_minute
                                : FeedMode::units_per_rev);
  }
  if (block_.has('f')) {
    modal_.feed_rate = block_.get('f');
    if (modal_.feed_mode != FeedMode::inverse_time) {
      emit(SetFeedRate{modal_.feed_rate});
    }
  }
}

// G93, G94 or G95: the feed rate starts again from 0 in the modes that keep one.
void Interpreter::Impl::set_feed_mode(FeedMode mode) {
  if (mode == FeedMode::inverse_time) {
    emit_comment("interpreter: feed mode set to inverse time");
    emit(SetFeedMode{FeedRateMode::per_minute});
  } else if (mode == FeedMode::units_per_minute) {
    emit_comment("interpreter: feed mode set to units per minute");
    emit(SetFeedMode{FeedRateMode::per_minute});
  } else {
    emit_comment("interpreter: feed mode set to units per revolution");
    emit(SetFeedMode{FeedRateMode::per_revolution});
  }
  modal_.feed_mode = mode;
  if (mode == FeedMode::inverse_time) return;
  modal_.feed_rate = 0;
  emit(SetFeedRate{0.0});
}

// M19: with R or P the spindle orients (R degrees from its index, 0 without R; P the way it
// turns there, its whole part as rs274 takes it, though the check lets 1.9996 pass as 2); with
// Q the program waits for it at most Q seconds. A bare M19 emits nothing, as in rs274; the
// spindle counts as stopped either way.
void Interpreter::Impl::orient_spindle() {
  modal_.spindle = SpindleDir::stopped;
  if (block_.has('r') || block_.has('p')) {
    emit(OrientSpindle{block_.has('r') ? block_.get('r') : 0.0,
                       block_.has('p') ? to_int(block_.get('p')) : 0});
  }
  if (block_.has('q')) {
    if (block_.get('q') <= 0.0) fail("Q word with M19 requires a value > 0", block_.col('q'));
    emit(WaitOrientSpindle{block_.get('q')});
  }
}

void Interpreter::Impl::do_tool_and_spindle() {
  if (block_.has('s')) {
    modal_.speed = block_.get('s');
    emit(SetSpindleSpeed{modal_.speed});
  }
  if (block_.has('t')) {
    const int tool = to_int(block_.get('t'));
    if (tool != 0 && tools_.find(tool) == nullptr && !options_.tool_table.empty()) {
      fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
           block_.col('t'));
    }
    tool_prepped_ = tool;
    emit(SelectTool{tool});
  }
  do_io();  // LinuxCNC's M codes start with group 5, before the tool change
  const int change = block_.m_code(MGroup::tool_change);
  if (change == 6) {
    if (comp_.on()) fail("Cannot change tools with cutter radius compensation on");
    const int tool = tool_prepped_ < 0 ? tool_in_spindle_ : tool_prepped_;
    emit(StartChange{});
    if (options_.tool_change_quill_up) {
      // Z up to machine zero, the other axes where they are.
      Pose machine = program_to_machine(pos_);
      machine[kZ] = 0;
      Pose up = pos_;
      up[kZ] = machine_to_program(machine)[kZ];
      emit(Comment{"AXIS,hide"});
      emit_straight(StraightKind::traverse, up);
      emit(Comment{"AXIS,show"});
    }
    if (!options_.tool_change_with_spindle_on) {
      emit(StopSpindleTurning{});
      modal_.spindle = SpindleDir::stopped;
    }
    emit(ChangeTool{tool, tools_.slot(tool)});
    tool_in_spindle_ = tool;
  } else if (change == 61) {
    if (!block_.has('q') || block_.get('q') < 0) {
      fail("Need non-negative Q-word to specify tool number with M61", block_.m_column[6]);
    }
    const int tool = to_int(block_.get('q'));
    tool_in_spindle_ = tool;
    emit(ChangeToolNumber{tool, tools_.slot(tool)});
  }
  switch (block_.m_code(MGroup::spindle)) {
    case 3:
      modal_.spindle = SpindleDir::clockwise;
      emit(StartSpindleClockwise{});
      break;
    case 4:
      modal_.spindle = SpindleDir::counterclockwise;
      emit(StartSpindleCounterclockwise{});
      break;
    case 5:
      modal_.spindle = SpindleDir::stopped;
      emit(StopSpindleTurning{});
      break;
    case 19:
      orient_spindle();
      break;
    default:  // M70-M73 share the group
      if (block_.m_code(MGroup::spindle) >= 70) do_modal_state(block_.m_code(MGroup::spindle));
      break;
  }
}

void Interpreter::Impl::do_coolant_and_overrides() {
  switch (block_.m_code(MGroup::coolant)) {
    case 7:
      modal_.mist = true;
      emit(MistOn{});
      break;
    case 8:
      modal_.flood = true;
      emit(FloodOn{});
      break;
    case 9:
      modal_.mist = modal_.flood = false;
      emit(MistOff{});
      emit(FloodOff{});
      break;
    default:
      break;
  }
  const int code = block_.m_code(MGroup::overrides);
  if (code < 0) return;
  // M48 turns both overrides on and M49 both off; M50-M53 turn theirs on, or off with P0.
  const bool has_p = block_.has('p');
  const bool on = code == 48 || (code != 49 && (!has_p || block_.get('p') != 0.0));
  if (comp_.on()) {
    fail(on ? "Cannot enable overrides with cutter radius compensation on"
            : "Cannot disable overrides with cutter radius compensation on");
  }
  if (code == 48 || code == 49 || code == 50) {
    modal_.overrides.feed = on;
    emit(SetFeedOverrideEnable{on});
  }
  if (code == 48 || code == 49 || code == 51) {
    modal_.overrides.speed = on;
    emit(SetSpindleOverrideEnable{on});
  }
  if (code == 52) {
    modal_.overrides.adaptive_feed = on;
    emit(SetAdaptiveFeedEnable{on});
  }
  if (code == 53) {
    modal_.overrides.feed_hold = on;
    emit(SetFeedHoldEnable{on});
  }
}

void Interpreter::Impl::do_dwell() {
  if (block_.g_code(GGroup::non_modal) != 40) return;
  if (!block_.has('p') || block_.get('p') < 0) {
    fail("Dwell time missing with g4", block_.g_column[0]);
  }
  emit(Dwell{block_.get('p')});
}

void Interpreter::Impl::do_modes() {
  const int plane = block_.g_code(GGroup::plane);
  if (plane >= 0) {
    Plane next = plane == 170 ? Plane::xy : plane == 180 ? Plane::xz : Plane::yz;
    if (plane == 171) next = Plane::uv;
    if (plane == 181) next = Plane::uw;
    if (plane == 191) next = Plane::vw;
    const int column = block_.g_column[static_cast<std::size_t>(GGroup::plane)];
    if (comp_.on() && next != modal_.plane) {
      fail("Cannot change planes with cutter radius compensation on", column);
    }
    if (comp_.on() && next != Plane::xy && next != Plane::xz) {
      fail("Cutter radius compensation allowed only in XY, XZ planes", column);
    }
    modal_.plane = next;
    emit(SelectPlane{modal_.plane});
  }
  const int units = block_.g_code(GGroup::units);
  if (units >= 0) change_units(units == 200 ? Units::inches : Units::mm);
  const int lathe = block_.g_code(GGroup::lathe_diameter);
  if (lathe >= 0) set_diameter_mode(lathe == 70);
  const int comp = block_.g_code(GGroup::cutter_comp);
  if (comp >= 0) Comp::comp_mode(*this, comp);
  const int length = block_.g_code(GGroup::tool_length);
  if (length >= 0) {
    if (comp_.on()) fail("Cannot change tool offset with cutter radius compensation on");
    apply_tool_length(length);
  }
  const int system = block_.g_code(GGroup::coord_system);
  if (system >= 0) {
    if (comp_.on()) fail("Cannot change coordinate systems with cutter radius compensation on");
    static constexpr int kSystems[] = {540, 550, 560, 570, 580, 590, 591, 592, 593};
    for (int i = 0; i < 9; ++i) {
      if (kSystems[i] != system) continue;
      if (i + 1 == modal_.coord_system) {
        emit_comment("interpreter: continuing to use same coordinate system");
      } else {
        select_coord_system(i + 1);
      }
    }
  }
  const int path = block_.g_code(GGroup::path_control);
  if (path >= 0) {
    if (comp_.on()) fail("Cannot change control mode with cutter radius compensation on");
    if (path == 610) {
      modal_.control = MotionMode::exact_path;
    } else if (path == 611) {
      modal_.control = MotionMode::exact_stop;
    } else {
      modal_.control = MotionMode::continuous;
      modal_.tolerance = block_.has('p') ? block_.get('p') : 0.0;
      modal_.naive_tolerance = block_.has('q') ? block_.get('q') : modal_.tolerance;
    }
    emit(SetMotionControlMode{modal_.control, modal_.tolerance});
    if (path == 640) emit(SetNaivecamTolerance{modal_.naive_tolerance});
  }
  const auto distance = block_.g_code(GGroup::distance);
  if (auto note = distance_mode_change(distance, 900, modal_.incremental, "distance");
      !note.empty())
    emit_comment(note);
  const auto arc_distance = block_.g_code(GGroup::arc_distance);
  if (auto note = distance_mode_change(arc_distance, 901, modal_.arc_incremental, "IJK distance");
      !note.empty())
    emit_comment(note);
  const int retract = block_.g_code(GGroup::retract);
  if (retract >= 0 && comp_.on()) {
    fail("Cannot change retract mode with cutter radius compensation on");
  }
  if (retract == 980) {
    modal_.retract_r_plane = false;
    emit_comment("interpreter: retract mode set to old_z");
  } else if (retract == 990) {
    modal_.retract_r_plane = true;
    emit_comment("interpreter: retract mode set to r_plane");
  }
}

void Interpreter::Impl::do_non_modal() {
  const int code = block_.g_code(GGroup::non_modal);
  if (comp_.on()) {
    if (code == 280 || code == 300) fail("Cannot use g28 or g30 with cutter radius comp");
    if (code == 281 || code == 301) {
      fail("Cannot set reference point with cutter compensation in effect");
    }
    if (code == 520 || (code >= 920 && code <= 923)) {
      fail("Cannot change axis offsets with cutter radius comp");
    }
    const int l = block_.has('l') ? to_int(block_.get('l')) : -1;
    const int p = block_.has('p') ? to_int(block_.get('p')) : -1;
    if (code == 100 && (l == 2 || l == 20) && (p == 0 || p == modal_.coord_system)) {
      fail("Cannot change the active coordinate system with cutter radius compensation on");
    }
  }
  switch (code) {
    case 100:
      do_g10();
      break;
    case 53:
      close_nurbs();
      break;
    case 280:
    case 281:
    case 300:
    case 301:
      do_home(code);
      break;
    case 520:
    case 920:
    case 921:
    case 922:
    case 923:
      do_g92(code);
      break;
    default:
      break;
  }
}

bool Interpreter::Impl::do_stop() {
  const int stop = block_.m_code(MGroup::stopping);
  if (stop == 0 || stop == 1 || stop == 60 || stop == 2 || stop == 30 || stop == 99) {
    Comp::comp_flush(*this);
  }
  switch (stop) {
    case 0:
      emit(ProgramStop{});
      return true;
    case 1:
      emit(OptionalProgramStop{});
      return true;
    case 60:
      emit(PalletShuttle{});
      emit(ProgramStop{});
      return true;
    case 2:
    case 30:
    case 99:  // M99 in the main program: LinuxCNC ends it as M2 does
      program_end_reset();
      ended_ = true;
      return true;
    default:
      return false;
  }
}

// What M2/M30 reset, in the order LinuxCNC emits it.
void Interpreter::Impl::program_end_reset() {
  comp_.side = CompSide::off;
  comp_.first_move = true;
  parameters_.hide_position(false);
  select_coord_system_quiet(1);
  emit_g5x();
  emit(SetXyRotation{rotation_deg_});
  if (modal_.plane != Plane::xy) {
    modal_.plane = Plane::xy;
    emit(SelectPlane{Plane::xy});
  }
  modal_.incremental = false;
  modal_.feed_mode = FeedMode::units_per_minute;
  emit(SetFeedMode{FeedRateMode::per_minute});
  modal_.feed_rate = 0;
  emit(SetFeedRate{0.0});
  if (!modal_.overrides.feed) {
    // LinuxCNC re-enables only the feed override here; the speed override stays as it was.
    modal_.overrides.feed = true;
    emit(SetFeedOverrideEnable{true});
  }
  modal_.spindle = SpindleDir::stopped;
  emit(StopSpindleTurning{});
  emit(SetSpindleMode{0.0});
  modal_.css = false;  // the canon is back in rpm mode (LinuxCNC's state keeps G96 here)
  modal_.css_max_rpm = 0;
  if (modal_.mist) emit(MistOff{});
  if (modal_.flood) emit(FloodOff{});
  modal_.mist = modal_.flood = false;
  modal_.motion = 10;
  nx_.cycle = 0;  // Numeryx: the end of the program ends the drilling cycle and its loops
  nx_loops_.clear();
  if (block_.m_code(MGroup::stopping) == 30) emit(PalletShuttle{});
  emit(ProgramEnd{});
  close_probe_file();
}

}  // namespace cncd::interp
