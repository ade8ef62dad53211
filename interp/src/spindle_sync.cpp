// Motion in step with the spindle: G33 (a straight feed, K per revolution) and G33.1 (rigid
// tapping down and back).
#include <algorithm>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

void Interpreter::Impl::do_spindle_synced(int code) {
  const std::string name = code == 330 ? "G33" : "G33.1";
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

}  // namespace cncd::interp
