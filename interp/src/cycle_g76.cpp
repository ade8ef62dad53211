// G76, the lathe threading cycle, as LinuxCNC's rs274 expands it: from where the tool stands
// (the drive line, X and Z) to Z, a series of passes in step with the spindle, each deeper
// than the last, then H spring passes at the full depth, each with optional tapers at its ends.
//
// The words: P pitch (distance per revolution), I the thread's peaks from the drive line
// (negative outside, positive inside), J the first pass's depth beyond the peaks, K the full
// depth, R the depth degression (pass n cuts J * n^(1/R) deep, R below 1 taken as 1), Q the
// compound slide angle (each pass moves depth * tan(Q) along the thread), H spring passes, E
// the length of the tapers along Z and L which ends get one (1 entry, 2 exit, 3 both).
// Under G7, I, J and K are diameters.
#include <cmath>
#include <numbers>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

constexpr const char* kG76 = "G76";
// One G76 block may not expand without bound (a tiny J with a large R, or a huge H).
constexpr int kMaxPasses = 10'000;

std::string with_g76(const char* what) {
  return std::string("In ") + kG76 + ", " + what;
}

}  // namespace

// The words G76 needs, checked with the block as rs274 checks them; and cncd's own check that
// G7 or G8 does not change the mode on the line (rs274 then takes I, J and K as a quarter or
// twice of what they are).
void Interpreter::Impl::check_threading_words() const {
  const Block& b = block_;
  // rs274 takes P-1 as no P.
  if (!b.has('p') || b.get('p') == -1.0) fail("P word missing with G76");
  if (!b.has('i') || !b.has('j') || !b.has('k')) fail("I J or K words missing with G76");
  const int lathe = b.g_code(GGroup::lathe_diameter);
  if (lathe >= 0 && (lathe == 70) != modal_.diameter_mode) {
    fail("Cannot change the lathe diameter mode (G7, G8) on a G76 line",
         b.g_column[static_cast<std::size_t>(GGroup::lathe_diameter)]);
  }
}

// rs274's checks in its order, then cncd's own: the refusals rs274 does not have are of
// programs it runs into motion no machine should make (a pitch of 0, a thread cut across the
// wrong plane, tapers longer than the thread, passes at no speed).
ThreadingCycle Interpreter::Impl::read_threading_cycle() const {
  const Block& b = block_;
  // cncd's own refusal: rs274 runs the passes through cutter compensation, which bends them.
  if (comp_.on()) fail("Cannot use G76 with cutter radius compensation on");
  if (modal_.spindle == SpindleDir::stopped) fail("Chosen spindle (0) not turning in G76");
  const Pose end = target_from_words();
  for (const int axis : {kA, kB, kC}) {
    const auto a = static_cast<std::size_t>(axis);
    if (end[a] != pos_[a]) fail("Cannot move rotary axes with G76", b.col(kAxisLetters[axis]));
  }
  ThreadingCycle t;
  // Under G7 the depths are diameters: the passes move the radius by half of them.
  const double scale = modal_.diameter_mode ? 0.5 : 1.0;
  t.i = b.get('i') * scale;
  t.j = b.get('j') * scale;
  t.k = b.get('k') * scale;
  if (t.i == 0.0) fail(with_g76("I must not be 0"), b.col('i'));
  if (t.j <= 0.0) fail(with_g76("J must be greater than 0"), b.col('j'));
  if (t.k <= t.j) fail(with_g76("K must be greater than J"), b.col('k'));

  // cncd's own checks from here on.
  for (const int axis : {kU, kV, kW}) {
    const auto a = static_cast<std::size_t>(axis);
    if (end[a] != pos_[a]) {
      fail("Cannot move U, V or W with G76: the thread is cut along X and Z",
           b.col(kAxisLetters[axis]));
    }
  }
  for (const char letter : {'x', 'y'}) {
    if (b.has(letter)) {
      fail(std::string("Cannot put ") + (letter == 'x' ? "an X" : "a Y") +
               " in G76: the drive line starts where the tool stands",
           b.col(letter));
    }
  }
  if (modal_.plane != Plane::xz) {
    fail("G76 cuts in the XZ plane: select it with G18 first",
         b.g_column[static_cast<std::size_t>(GGroup::motion)]);
  }
  t.pitch = b.get('p');
  if (!(t.pitch > 0.0)) {
    fail("P word must be positive with G76 (the distance per revolution)", b.col('p'));
  }
  if (modal_.speed == 0.0) fail("Cannot do G76 with zero spindle speed");
  t.x0 = pos_[kX];
  t.z0 = pos_[kZ];
  t.z1 = end[kZ];
  if (t.z1 == t.z0) fail("Cannot do G76 with Z where the tool stands: the thread has no length");
  if (b.has('l') && b.get('l') > 3) {
    fail("L word must be 0, 1, 2 or 3 with G76 (no taper, entry, exit, both)", b.col('l'));
  }
  const int ends = b.has('l') ? to_int(b.get('l')) : 0;
  const double taper = b.has('e') ? b.get('e') : 0.0;
  if (taper > 0.0) {
    t.taper = taper;
    t.entry_taper = (ends & 1) != 0;
    t.exit_taper = (ends & 2) != 0;
  }
  const int tapers = (t.entry_taper ? 1 : 0) + (t.exit_taper ? 1 : 0);
  if (tapers * t.taper > std::fabs(t.z1 - t.z0)) {
    fail("E word too long with G76: the tapers would be longer than the thread", b.col('e'));
  }
  t.degression = b.has('r') && b.get('r') >= 1.0 ? b.get('r') : 1.0;
  t.tan_q = b.has('q') ? std::tan(b.get('q') * std::numbers::pi / 180.0) : 0.0;
  t.spring_passes = b.has('h') ? to_int(b.get('h')) : 0;
  return t;
}

// One pass `depth` beyond the peaks. The pass moves `depth` * tan(Q) along the thread from the
// drive line's start, and ends short of Z by (K - depth) * tan(Q); back out, the tool clears
// the drive line by as much as it is short of the full depth.
void Interpreter::Impl::threading_pass(const ThreadingCycle& t, double depth) {
  const double inward = t.i > 0.0 ? 1.0 : -1.0;  // the way X cuts: + inside, - outside
  const double along = t.z1 > t.z0 ? 1.0 : -1.0;
  const double cut_x = t.x0 + inward * (std::fabs(t.i) + depth);
  const double clear_x = t.x0 - inward * (t.k - depth);
  const double taper_x = cut_x - inward * t.k;  // where a taper leaves the full thread's depth
  const double start_z = t.z0 + along * depth * t.tan_q;
  const double end_z = t.z1 + along * (depth - t.k) * t.tan_q;
  const double taper_pitch = t.pitch * std::hypot(t.k, t.taper) / t.taper;
  auto at = [&](double x, double z) {
    Pose p = pos_;
    p[kX] = x;
    p[kZ] = z;
    return p;
  };
  emit_straight(StraightKind::traverse, at(clear_x, start_z));
  if (t.entry_taper) {
    emit(SetFeedOverrideEnable{false});
    emit(StartSpeedFeedSynch{taper_pitch, false});
    emit_straight(StraightKind::feed, at(taper_x, start_z));
    emit_straight(StraightKind::feed, at(cut_x, start_z + along * t.taper));
    emit(StartSpeedFeedSynch{t.pitch, false});
  } else {
    emit_straight(StraightKind::traverse, at(cut_x, start_z));
    emit(SetFeedOverrideEnable{false});
    emit(StartSpeedFeedSynch{t.pitch, false});
  }
  if (t.exit_taper) {
    emit_straight(StraightKind::feed, at(cut_x, end_z - along * t.taper));
    emit(StartSpeedFeedSynch{taper_pitch, false});
    emit_straight(StraightKind::feed, at(taper_x, end_z));
  } else {
    emit_straight(StraightKind::feed, at(cut_x, end_z));
  }
  emit(StopSpeedFeedSynch{});
  emit_straight(StraightKind::traverse, at(clear_x, end_z));
  emit(SetFeedOverrideEnable{true});
}

// The passes go deeper while the next depth is short of K (compared, as rs274 does, with I's
// offset added to both: a pass a rounding error short of K is the full-depth pass); then the
// full-depth pass, the spring passes, and the tool goes back out to the drive line at Z.
void Interpreter::Impl::do_threading_cycle() {
  const ThreadingCycle t = read_threading_cycle();
  const double peaks = std::fabs(t.i);
  const double full = peaks + t.k;
  auto depth_of = [&](int pass) {
    return pass == 1 ? t.j : t.j * std::pow(static_cast<double>(pass), 1.0 / t.degression);
  };
  int deepening = 0;  // the passes short of K
  while (deepening <= kMaxPasses && peaks + depth_of(deepening + 1) < full)
    ++deepening;
  if (deepening + 1 + t.spring_passes > kMaxPasses) {
    fail("G76 would cut more than " + std::to_string(kMaxPasses) +
         " passes: J too small for K at this R, or H too large");
  }
  for (int pass = 1; pass <= deepening; ++pass)
    threading_pass(t, depth_of(pass));
  for (int pass = 0; pass <= t.spring_passes; ++pass)
    threading_pass(t, t.k);
  Pose out = pos_;
  out[kX] = t.x0;
  out[kZ] = t.z1;
  emit_straight(StraightKind::traverse, out);
}

}  // namespace cncd::interp
