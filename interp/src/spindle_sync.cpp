// Motion in step with the spindle: G33 (a straight feed, K per revolution), G33.1 (rigid
// tapping down and back) and the rigid G84/G74 holes of canned cycles (InterpOptions::
// rigid_tapping, and the Numeryx g74).
#include <algorithm>
#include <cstdio>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

std::string number(double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

}  // namespace

void Interpreter::Impl::do_spindle_synced(int code) {
  const std::string name = code == 330 ? "G33" : "G33.1";
  // cncd's own refusal: rs274 offsets the move and drops its spindle synchronisation (a thread
  // cut at the feed rate), or fails with an internal error.
  if (comp_.on()) fail("Cannot use " + name + " with cutter radius compensation on");
  if (modal_.spindle == SpindleDir::stopped) fail("Spindle not turning in " + name);
  // cncd's own checks: LinuxCNC would start the move and wait for a spindle that never turns,
  // or for a position that never comes.
  if (modal_.speed == 0.0) fail("Cannot do " + name + " with zero spindle speed");
  const double pitch = block_.get('k');
  if (!(pitch > 0.0)) {
    fail("K word must be positive with " + name + " (the distance per revolution)",
         block_.col('k'));
  }
  const Pose end = target_from_words();
  if (code == 330) {
    emit(StartSpeedFeedSynch{pitch, false});
    emit_straight(StraightKind::feed, end);
    emit(StopSpeedFeedSynch{});
    return;
  }
  // LinuxCNC's canon leaves A B C U V W out of the tap while its interpreter takes them as
  // moved, so the next move would turn them: refused.
  for (int axis = kA; axis < kAxes; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    if (end[a] != pos_[a]) {
      fail("Cannot move A, B, C, U, V or W with G33.1: the tap moves along X, Y and Z",
           block_.col(kAxisLetters[axis]));
    }
  }
  // I: the spindle runs I times as fast on the way out (at least 1).
  const double scale = block_.has('i') ? std::max(block_.get('i'), 1.0) : 1.0;
  emit(StartSpeedFeedSynch{pitch, false});
  emit(RigidTap{end, scale});
  emit(StopSpeedFeedSynch{});
  // The tap ends where it started.
}

bool Interpreter::Impl::tapping_is_rigid(int code) const {
  if (dialect_ == Dialect::numeryx && code == 740) return true;
  return options_.rigid_tapping;
}

// One rigid hole from the R plane, where the approach left the tool: in step with the spindle
// down to the bottom and back to R (RIGID_TAP reverses the spindle at the bottom and again at
// R), then out to the clear height. The pitch: F in G95 and F/S in G94; in the Numeryx dialect
// F in thousandths of the program's unit (its note: f1250 = 1.25 mm, f125 = 0.125 in). A dwell
// at the bottom (P, D) has no place in it: the machine reverses the spindle there.
void Interpreter::Impl::rigid_tap_hole(int code, const CycleGeometry& g, double a, double b,
                                       double& current_c) {
  const bool numeryx = dialect_ == Dialect::numeryx;
  const std::string name = numeryx ? "g" + std::to_string(code / 10) : code == 840 ? "G84" : "G74";
  // Numeryx taps right-hand with g74 and g84 alike, and needs no M3: a spindle at rest is
  // started for the hole and stopped after it.
  const bool right_hand = numeryx || code == 840;
  bool start_here = false;
  if (modal_.spindle == SpindleDir::stopped) {
    if (!numeryx) fail("Spindle not turning in " + name);
    start_here = true;
  }
  if (right_hand && modal_.spindle == SpindleDir::counterclockwise) {
    fail("Spindle turning counterclockwise in " + name +
         (numeryx ? ": Numeryx taps right-hand with g74 and g84" : ""));
  }
  if (!right_hand && modal_.spindle == SpindleDir::clockwise) {
    fail("Spindle turning clockwise in " + name);
  }
  double pitch = modal_.feed_rate;
  if (numeryx) {
    if (modal_.speed == 0.0) fail("Cannot do rigid tapping with zero spindle speed in " + name);
    pitch = modal_.feed_rate / 1000.0;
    const bool inch = modal_.units == Units::inches;
    if (pitch < (inch ? 0.002 : 0.05)) {
      fail("Tapping pitch F" + number(modal_.feed_rate) + " is " + number(pitch) +
               (inch ? " in" : " mm") +
               " per revolution: in the Numeryx dialect F gives the pitch in thousandths " +
               (inch ? "of an inch (f125 = 0.125 in)" : "of a mm (f1250 = 1.25 mm)"),
           block_.has('f') ? block_.col('f') : 0);
    }
  } else if (modal_.feed_mode == FeedMode::units_per_minute) {
    if (modal_.speed == 0.0) {
      fail("Cannot do rigid tapping with zero spindle speed in " + name +
           ": the pitch is F/S in G94");
    }
    if (modal_.css) {
      fail("Cannot do rigid tapping in " + name +
           " with constant surface speed: the pitch is F/S in G94, with S in rpm (G97)");
    }
    pitch = modal_.feed_rate / modal_.speed;
  } else if (modal_.speed == 0.0) {
    fail("Cannot do rigid tapping with zero spindle speed in " + name);
  }
  if (start_here) emit(StartSpindleClockwise{});
  emit(StartSpeedFeedSynch{pitch, false});
  Pose bottom = pos_;
  bottom[g.a] = a;
  bottom[g.b] = b;
  bottom[g.c] = g.bottom;
  emit(RigidTap{bottom, 1.0});
  emit(StopSpeedFeedSynch{});
  current_c = pos_[g.c];
  if (current_c != g.clear) {
    Pose out = pos_;
    out[g.c] = g.clear;
    emit_straight(StraightKind::traverse, out);
    current_c = g.clear;
  }
  if (start_here) emit(StopSpindleTurning{});
}

}  // namespace cncd::interp
