// Canned cycles G73, G74, G81-G89 in the six planes, with L repeats, G98/G99 and absolute
// or incremental distances, expanded into straight moves, dwells and spindle commands in the
// order LinuxCNC emits them (including where its errors interrupt a cycle).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <numbers>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

// As LinuxCNC's messages name the planes: the XYZ ones in lower case in most of them, the UVW
// ones always in upper case.
const char* plane_name(Plane plane) {
  constexpr const char* kNames[] = {"xy", "yz", "xz", "UV", "VW", "UW"};  // from Plane::xy = 1
  const std::size_t index = static_cast<std::size_t>(plane) - 1;
  return index < std::size(kNames) ? kNames[index] : kNames[0];
}

bool is_uvw_plane(Plane plane) {
  return plane == Plane::uv || plane == Plane::vw || plane == Plane::uw;
}

bool is_canned_cycle(int code) {
  return code == 730 || code == 740 || (code >= 810 && code <= 890);
}

std::string g_name(int code) {
  return "g" + std::to_string(code / 10);
}

constexpr double kDegree = std::numbers::pi / 180.0;
// One cycle block may not expand without bound: L repeats and G73/G83 pecks are limited (a Q
// too small for the depth would otherwise never reach the bottom in floating point).
constexpr int kMaxCycleRepeats = 100'000;
constexpr int kMaxPecks = 100'000;

// LinuxCNC's chip-break and peck clearance: 0.010 inch.
double peck_clearance(Units units) {
  return units == Units::inches ? 0.010 : 0.254;
}

}  // namespace

// A cycle in an XYZ plane moves no U, V or W, and one in a UVW plane no X, Y or Z.
void Interpreter::Impl::check_cycle_plane_words() const {
  const bool uvw = is_uvw_plane(modal_.plane);
  const char* plane = modal_.plane == Plane::xz   ? "XZ"
                      : modal_.plane == Plane::yz ? "YZ"
                      : uvw                       ? plane_name(modal_.plane)
                                                  : "XY";
  for (const char letter : uvw ? "xyz" : "uvw") {
    if (letter == '\0' || !block_.has(letter)) continue;
    const char upper = static_cast<char>(std::toupper(letter));
    fail(std::string("Cannot put ") + (upper == 'X' ? "an " : "a ") + upper +
             " in a canned cycle in the " + plane + " plane",
         block_.col(letter));
  }
}

void Interpreter::Impl::do_canned_cycle(int code) {
  CycleGeometry g;
  const PlaneAxes axes = plane_axes(modal_.plane);
  g.a = axes.first;
  g.b = axes.second;
  g.c = axes.normal;
  const char c_letter = kAxisLetters[g.c];
  const bool same_cycle = previous_motion_ == code;

  if (modal_.feed_rate == 0.0) fail("Cannot feed with zero feed rate");
  if (modal_.feed_mode == FeedMode::inverse_time) {
    fail("Cannot use inverse time feed with canned cycles");
  }
  if (block_.has('r')) {
    cycle_.r = block_.get('r');
  } else if (!same_cycle) {
    fail("R clearance plane unspecified in cycle");
  }
  int repeats = 1;
  if (block_.has('l')) {
    repeats = to_int(block_.get('l'));
    if (repeats == 0) fail("Cannot do zero repeats of cycle", block_.col('l'));
    if (repeats > kMaxCycleRepeats) {
      fail("Too many repeats of cycle (L more than " + std::to_string(kMaxCycleRepeats) + ")",
           block_.col('l'));
    }
  }
  check_cycle_plane_words();

  if (block_.has(c_letter)) {
    cycle_.z = block_.get(c_letter);
  } else if (!same_cycle) {
    fail(std::string(1, static_cast<char>(std::toupper(c_letter))) + " value unspecified in " +
         plane_name(modal_.plane) + " plane canned cycle");
  }

  if (!is_canned_cycle(previous_motion_)) cycle_.initial_level = pos_[g.c];
  double old_c = cycle_.initial_level;
  g.r = cycle_.r;
  g.bottom = cycle_.z;
  if (modal_.incremental) {
    g.r += old_c;
    g.bottom += g.r;
  }
  if (g.r < g.bottom) {
    const char letter =
        is_uvw_plane(modal_.plane) ? static_cast<char>(std::toupper(c_letter)) : c_letter;
    fail(std::string("R less than ") + letter + " in cycle in " + plane_name(modal_.plane) +
         " plane");
  }
  if (old_c < g.r) {
    // Below the R plane: go up to it first, once for all repeats.
    Pose up = pos_;
    up[g.c] = g.r;
    emit_straight(StraightKind::traverse, up);
    old_c = g.r;
  }
  g.clear = (!modal_.retract_r_plane && old_c > g.r) ? old_c : g.r;

  const bool switch_mode = modal_.control != MotionMode::exact_path;
  if (switch_mode) {
    emit(SetMotionControlMode{MotionMode::exact_path, 0.0});
  }
  // Cycle-specific words, checked once the cycle has started (as LinuxCNC does).
  const bool needs_p = code == 820 || code == 860 || code == 880 || code == 890;
  if (block_.has('p')) cycle_.p = block_.get('p');
  if (needs_p && !block_.has('p') && !same_cycle) {
    fail("Dwell time p word missing with " + g_name(code));
  }
  if (code == 730 || code == 830) {
    if (block_.has('q')) cycle_.q = block_.get('q');
    if ((!block_.has('q') && !same_cycle) || cycle_.q <= 0.0) {
      fail("Q word missing with " + g_name(code));
    }
  }
  if (code == 870) {
    // I, J and K belong to X, Y and Z: the plane axes' letters give the entry offset, the
    // drilling axis' letter the height the back bore cuts up to.
    // (U, V and W take I, J and K as X, Y and Z do.)
    static constexpr char kOffsetLetters[] = "ijk";
    for (const char letter : {'i', 'j', 'k'}) {
      if (block_.has(letter)) {
        (letter == 'i' ? cycle_.i : letter == 'j' ? cycle_.j : cycle_.k) = block_.get(letter);
      } else if (!same_cycle) {
        fail(std::string(1, static_cast<char>(std::toupper(letter))) + " word missing with g87");
      }
    }
    auto value_of = [this](char letter) {
      return letter == 'i' ? cycle_.i : letter == 'j' ? cycle_.j : cycle_.k;
    };
    g.i = value_of(kOffsetLetters[g.a % 3]);
    g.j = value_of(kOffsetLetters[g.b % 3]);
    const double height = value_of(kOffsetLetters[g.c % 3]);
    g.k = modal_.incremental ? g.bottom + height : height;
  }

  const char a_letter = kAxisLetters[g.a];
  const char b_letter = kAxisLetters[g.b];
  double a = pos_[g.a];
  double b = pos_[g.b];
  // The first move across the plane stays clear of the work: at the current height, or at the
  // retract height when that is higher.
  double current_c = std::max(pos_[g.c], g.clear);
  const bool polar =
      modal_.plane == Plane::xy && (block_.has_polar_distance || block_.has_polar_angle);
  for (int repeat = 0; repeat < repeats; ++repeat) {
    if (polar) {
      // Polar words place the hole around the XY origin; incremental ones step the distance
      // and angle from the previous hole.
      double distance = std::hypot(a, b);
      double angle = std::atan2(b, a) / kDegree;
      if (block_.has_polar_distance) {
        distance = modal_.incremental ? distance + block_.polar_distance : block_.polar_distance;
      }
      if (block_.has_polar_angle) {
        angle = modal_.incremental ? angle + block_.polar_angle : block_.polar_angle;
      }
      a = distance * std::cos(angle * kDegree);
      b = distance * std::sin(angle * kDegree);
    } else if (modal_.incremental) {
      a += block_.has(a_letter) ? block_.get(a_letter) : 0.0;
      b += block_.has(b_letter) ? block_.get(b_letter) : 0.0;
    } else {
      a = block_.has(a_letter) ? block_.get(a_letter) : a;
      b = block_.has(b_letter) ? block_.get(b_letter) : b;
    }
    cycle_body(code, g, a, b, current_c);
  }
  if (switch_mode) {
    emit(SetMotionControlMode{modal_.control, modal_.tolerance});
    emit(SetNaivecamTolerance{modal_.naive_tolerance});
  }
}

// One repeat: across the plane to (a, b), down to R, the cycle's own moves, and out to the
// clear height (`current_c` tracks the drilling-axis position between moves).
void Interpreter::Impl::cycle_body(int code, const CycleGeometry& g, double a, double b,
                                   double& current_c) {
  auto move = [&](StraightKind kind, double a_value, double b_value, double c_value) {
    Pose end = pos_;
    end[g.a] = a_value;
    end[g.b] = b_value;
    end[g.c] = c_value;
    emit_straight(kind, end);
    current_c = c_value;
  };
  auto traverse = [&](double c_value) { move(StraightKind::traverse, a, b, c_value); };
  auto feed = [&](double c_value) { move(StraightKind::feed, a, b, c_value); };
  auto dwell = [&](double seconds) { emit(Dwell{seconds}); };
  auto start_spindle = [&](bool counterclockwise) {
    if (counterclockwise) {
      emit(StartSpindleCounterclockwise{});
    } else {
      emit(StartSpindleClockwise{});
    }
  };
  const bool restart_counterclockwise = modal_.spindle == SpindleDir::counterclockwise;
  auto restart = [&] { start_spindle(restart_counterclockwise); };

  if (g.position_first) traverse(current_c);
  if (current_c != g.r) traverse(g.r);
  // The dwell at the bottom: LinuxCNC's P for the cycles that take one; the Numeryx D for all.
  auto dwell_at_bottom = [&](bool takes_p) {
    if (g.dwell) {
      if (*g.dwell > 0) dwell(*g.dwell);
    } else if (takes_p) {
      dwell(cycle_.p);
    }
  };
  if ((code == 740 || code == 840) && tapping_is_rigid(code)) {
    rigid_tap_hole(code, g, a, b, current_c);
    return;
  }
  const bool needs_spindle =
      code == 740 || code == 840 || code == 860 || code == 870 || code == 880;
  if (needs_spindle && modal_.spindle == SpindleDir::stopped) {
    fail("Spindle not turning in " +
         (code == 840 || code == 740 ? "G" + std::to_string(code / 10) : g_name(code)));
  }
  switch (code) {
    case 810:
      feed(g.bottom);
      dwell_at_bottom(false);
      traverse(g.clear);
      break;
    case 820:
      feed(g.bottom);
      dwell_at_bottom(true);
      traverse(g.clear);
      break;
    case 730:
    case 830: {
      const double clearance = peck_clearance(modal_.units);
      int pecks = 0;
      for (double depth = g.peck_top.value_or(g.r) - cycle_.q; depth > g.bottom;
           depth -= cycle_.q) {
        if (++pecks > kMaxPecks) {
          fail("Too many pecks in " + g_name(code) + ": Q too small for the depth (more than " +
               std::to_string(kMaxPecks) + " pecks)");
        }
        feed(depth);
        if (code == 830) traverse(g.r);
        traverse(depth + clearance);
      }
      feed(g.bottom);
      dwell_at_bottom(false);
      traverse(g.clear);
      break;
    }
    case 740:
    case 840: {
      const bool right_hand = code == 840;
      if (right_hand && modal_.spindle == SpindleDir::counterclockwise) {
        fail("Spindle turning counterclockwise in G84");
      }
      if (!right_hand && modal_.spindle == SpindleDir::clockwise) {
        fail("Spindle turning clockwise in G74");
      }
      emit(SetFeedOverrideEnable{false});
      emit(SetSpindleOverrideEnable{false});
      feed(g.bottom);
      emit(StopSpindleTurning{});
      start_spindle(right_hand);
      dwell_at_bottom(true);
      feed(g.clear);
      emit(StopSpindleTurning{});
      start_spindle(!right_hand);
      emit(SetFeedOverrideEnable{true});
      emit(SetSpindleOverrideEnable{true});
      break;
    }
    case 850:
      feed(g.bottom);
      dwell_at_bottom(false);
      feed(g.r);
      traverse(g.clear);
      break;
    case 860:
      feed(g.bottom);
      dwell_at_bottom(true);
      emit(StopSpindleTurning{});
      traverse(g.clear);
      restart();
      break;
    case 870: {
      // Back boring: enter beside the hole with the spindle oriented, cut upwards to K.
      const double off_a = a + g.i;
      const double off_b = b + g.j;
      auto offset_traverse = [&](double c_value) {
        move(StraightKind::traverse, off_a, off_b, c_value);
      };
      offset_traverse(current_c);
      emit(StopSpindleTurning{});
      emit(OrientSpindle{0.0, 2});
      offset_traverse(g.bottom);
      traverse(g.bottom);
      restart();
      feed(g.k);
      feed(g.bottom);
      emit(StopSpindleTurning{});
      emit(OrientSpindle{0.0, 2});
      offset_traverse(g.bottom);
      offset_traverse(g.clear);
      traverse(g.clear);
      restart();
      break;
    }
    case 880:
      feed(g.bottom);
      dwell(cycle_.p);
      emit(StopSpindleTurning{});
      emit(ProgramStop{});
      restart();
      // The operator retracts by hand during the stop; LinuxCNC then takes the tool to be at
      // the clear height.
      pos_[g.c] = g.clear;
      current_c = g.clear;
      break;
    case 890:
      feed(g.bottom);
      dwell(cycle_.p);
      feed(g.clear);
      break;
    default:
      fail("G" + std::to_string(code / 10) + " is not supported");
  }
}

}  // namespace cncd::interp
