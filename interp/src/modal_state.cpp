// M70-M73 as LinuxCNC 2.9 runs them: M70 saves the modal state of the current call level, M71
// forgets it, M72 restores it and M73 saves it to be restored when the subroutine returns.
// A restore changes only what differs from the saved state, in rs274's order and with the
// canon each change's G or M code prints; where rs274 restores something other than what was
// saved, cncd restores what was saved (docs/interpreter.md lists the cases).
#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

SavedModalState& Interpreter::Impl::saved_modal_state() {
  return calls_.empty() ? saved_modal_top_ : calls_.back().saved_modal;
}

// rs274 drops whatever an M72 line says after M72 once the restore changed anything (M72 G0 X1
// does not move, M72 M2 does not end the program): cncd refuses such a line instead.
void Interpreter::Impl::check_modal_state_line() const {
  const int code = block_.m_code(MGroup::spindle);
  if (code < 70 || code > 73) return;
  const int column = block_.m_column[static_cast<std::size_t>(MGroup::spindle)];
  if (dialect_ == Dialect::numeryx)
    fail("M" + std::to_string(code) + " is not supported in the Numeryx dialect", column);
  if (code != 72) return;
  if (block_has_other_words())
    fail("An M72 line takes no other words: put them on a line of their own", column);
}

// Any word but N, comments and the one M code: a letter, a G code, another M code, polar words.
bool Interpreter::Impl::block_has_other_words() const {
  bool g_codes = false;
  for (const int g : block_.g)
    g_codes = g_codes || g >= 0;
  return block_.present != 0 || g_codes || block_.m_count > 1 || block_.has_polar_distance ||
         block_.has_polar_angle;
}

void Interpreter::Impl::do_modal_state(int code) {
  SavedModalState& saved = saved_modal_state();
  switch (code) {
    case 70:
    case 73:
      saved.valid = true;
      // M73 in the main program saves as M70 does: there is no return to restore it.
      saved.auto_restore = code == 73 && !calls_.empty();
      saved.modal = modal_;
      saved.tool_offset = tool_offset_;
      saved.g92_applied = parameters_.get(5210) != 0.0;
      saved.comp_side = comp_.side;
      return;
    case 71:
      saved = SavedModalState{};
      return;
    default:
      if (!saved.valid) {
        fail("Cannot restore context from invalid stack frame - missing M70/M73?",
             block_.m_column[static_cast<std::size_t>(MGroup::spindle)]);
      }
      restore_modal_state(SavedModalState(saved));
      return;
  }
}

void Interpreter::Impl::auto_restore_modal_state() {
  if (calls_.empty()) return;
  const SavedModalState& saved = calls_.back().saved_modal;
  if (saved.valid && saved.auto_restore) restore_modal_state(SavedModalState(saved));
}

void Interpreter::Impl::restore_modal_state(const SavedModalState& saved) {
  const ModalState& m = saved.modal;
  // Units first: the feed and speed compare as the numbers they were written as.
  if (m.units != modal_.units) change_units(m.units);
  if (m.css != modal_.css || m.css_max_rpm != modal_.css_max_rpm) {
    // rs274 restores G96 without its D (a limit of 1e30 rpm); cncd keeps the saved limit.
    modal_.css = m.css;
    modal_.css_max_rpm = m.css_max_rpm;
    emit(SetSpindleMode{m.css_max_rpm});
  }
  const FeedMode mode_before = modal_.feed_mode;
  const double feed_before = modal_.feed_rate;
  if (m.feed_mode != modal_.feed_mode) set_feed_mode(m.feed_mode);
  if (m.feed_mode == FeedMode::inverse_time) {
    modal_.feed_rate = m.feed_rate;  // each inverse-time move gives its own F
  } else if (m.feed_rate != modal_.feed_rate ||
             (mode_before != FeedMode::inverse_time && m.feed_rate != feed_before)) {
    // rs274 sets F when it differs from the feed before the restore, and loses it (leaves 0)
    // when the feed mode changes to what it was; cncd restores it then too.
    modal_.feed_rate = m.feed_rate;
    emit(SetFeedRate{m.feed_rate});
  }
  if (m.speed != modal_.speed) {
    modal_.speed = m.speed;
    emit(SetSpindleSpeed{m.speed});
  }
  // rs274 restores the first of the spindle, the coolant and the overrides that changed here
  // and the others after the G codes.
  const bool spindle_changed = m.spindle != modal_.spindle;
  if (spindle_changed) {
    modal_.spindle = m.spindle;
    if (m.spindle == SpindleDir::clockwise) {
      emit(StartSpindleClockwise{});
    } else if (m.spindle == SpindleDir::counterclockwise) {
      emit(StartSpindleCounterclockwise{});
    } else {
      emit(StopSpindleTurning{});
    }
  }
  const bool coolant_changed = m.mist != modal_.mist || m.flood != modal_.flood;
  const bool overrides_changed = m.overrides != modal_.overrides;
  const bool coolant_later = coolant_changed && spindle_changed;
  const bool overrides_later = overrides_changed && (spindle_changed || coolant_changed);
  if (!coolant_later) restore_coolant(m);
  if (!overrides_later) restore_overrides(m);
  restore_modes(saved);
  if (coolant_later) restore_coolant(m);
  if (overrides_later) restore_overrides(m);
}

// What is on and was not is turned off with both (as M9), then what was on comes back. rs274
// turns nothing off while any saved coolant was on (M7 saved, M8 now: both stay on).
void Interpreter::Impl::restore_coolant(const ModalState& m) {
  if ((modal_.mist && !m.mist) || (modal_.flood && !m.flood)) {
    modal_.mist = modal_.flood = false;
    emit(MistOff{});
    emit(FloodOff{});
  }
  if (m.mist && !modal_.mist) {
    modal_.mist = true;
    emit(MistOn{});
  }
  if (m.flood && !modal_.flood) {
    modal_.flood = true;
    emit(FloodOn{});
  }
}

// The G codes' modes, in rs274's order.
void Interpreter::Impl::restore_modes(const SavedModalState& saved) {
  const ModalState& m = saved.modal;
  if (m.plane != modal_.plane) {
    modal_.plane = m.plane;
    emit(SelectPlane{m.plane});
  }
  set_diameter_mode(m.diameter_mode);
  if (saved.comp_side != comp_.side) {
    // As rs274 does it: G40, or G41/G42 with the tool in the spindle's radius.
    Comp::comp_mode(*this, saved.comp_side == CompSide::off    ? 400
                           : saved.comp_side == CompSide::left ? 410
                                                               : 420);
  }
  if (modal_.tool_length_code != m.tool_length_code) {
    if (m.tool_length_code == 430 || m.tool_length_code == 490) {
      apply_tool_length(m.tool_length_code);  // G43: the tool in the spindle, as rs274
    } else {
      // rs274 restores G43.1 and G43.2 as G43 (the table's offset of the tool in the
      // spindle); cncd restores the offsets they gave.
      for (std::size_t axis = 0; axis < kAxes; ++axis)
        pos_[axis] += tool_offset_[axis] - saved.tool_offset[axis];
      tool_offset_ = saved.tool_offset;
      for (int axis = 0; axis < kAxes; ++axis) {
        const auto a = static_cast<std::size_t>(axis);
        tool_offset_machine_[a] =
            is_linear_axis(axis) ? to_machine_units(tool_offset_[a]) : tool_offset_[a];
      }
      modal_.tool_length_code = m.tool_length_code;
      emit(UseToolLengthOffset{tool_offset_});
    }
  }
  if (m.coord_system != modal_.coord_system) select_coord_system(m.coord_system);
  if (m.control != modal_.control ||
      (m.control == MotionMode::continuous &&
       (m.tolerance != modal_.tolerance || m.naive_tolerance != modal_.naive_tolerance))) {
    modal_.control = m.control;
    modal_.tolerance = m.tolerance;
    modal_.naive_tolerance = m.naive_tolerance;
    emit(SetMotionControlMode{m.control, m.tolerance});
    if (m.control == MotionMode::continuous) emit(SetNaivecamTolerance{m.naive_tolerance});
  }
  if (m.incremental != modal_.incremental) {
    modal_.incremental = m.incremental;
    emit_comment(m.incremental ? "interpreter: distance mode changed to incremental"
                               : "interpreter: distance mode changed to absolute");
  }
  if (m.arc_incremental != modal_.arc_incremental) {
    modal_.arc_incremental = m.arc_incremental;
    emit_comment(m.arc_incremental ? "interpreter: IJK distance mode changed to incremental"
                                   : "interpreter: IJK distance mode changed to absolute");
  }
  if (m.retract_r_plane != modal_.retract_r_plane) {
    modal_.retract_r_plane = m.retract_r_plane;
    emit_comment(m.retract_r_plane ? "interpreter: retract mode set to r_plane"
                                   : "interpreter: retract mode set to old_z");
  }
  // The G92 offset as enabled or not: off as G92.2 turns it off, on from its parameters as
  // G92.3 (the offset itself is not saved).
  if (saved.g92_applied != (parameters_.get(5210) != 0.0)) do_g92(saved.g92_applied ? 923 : 922);
}

// The feed and speed override switches (as M48/M49 print them when both change the same way),
// adaptive feed and feed hold. rs274 restores M48/M49 only, and wrongly from M49 or M50-M53.
void Interpreter::Impl::restore_overrides(const ModalState& m) {
  const auto restore = [this](bool& current, bool saved, auto op) {
    if (current == saved) return;
    current = saved;
    op.on = saved;
    emit(op);
  };
  restore(modal_.overrides.feed, m.overrides.feed, SetFeedOverrideEnable{});
  restore(modal_.overrides.speed, m.overrides.speed, SetSpindleOverrideEnable{});
  restore(modal_.overrides.adaptive_feed, m.overrides.adaptive_feed, SetAdaptiveFeedEnable{});
  restore(modal_.overrides.feed_hold, m.overrides.feed_hold, SetFeedHoldEnable{});
}

}  // namespace cncd::interp
