// Canned cycles G73, G74, G81-G89 in the three planes, with L repeats, G98/G99 and absolute
// or incremental distances, expanded into straight moves, dwells and spindle commands.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

struct CycleAxes {
  int a;  // first plane axis
  int b;  // second plane axis
  int c;  // drilling axis
  const char* plane;
};

CycleAxes cycle_axes(Plane plane) {
  switch (plane) {
    case Plane::xz:
      return {kZ, kX, kY, "xz"};
    case Plane::yz:
      return {kY, kZ, kX, "yz"};
    case Plane::xy:
    default:
      return {kX, kY, kZ, "xy"};
  }
}

}  // namespace

void Interpreter::Impl::do_canned_cycle(int code) {
  const CycleAxes axes = cycle_axes(modal_.plane);
  const char a_letter = kAxisLetters[axes.a];
  const char b_letter = kAxisLetters[axes.b];
  const char c_letter = kAxisLetters[axes.c];
  const bool same_cycle = previous_motion_ == code;
  const auto ca = static_cast<std::size_t>(axes.a);
  const auto cb = static_cast<std::size_t>(axes.b);

  for (const char letter : {'a', 'b', 'c'}) {
    if (block_.has(letter)) fail("Cannot put an a, b, or c in canned cycle", block_.col(letter));
  }
  if (block_.has('r')) {
    cycle_.r = block_.get('r');
  } else if (!same_cycle) {
    fail("R clearance plane unspecified in cycle");
  }
  if (block_.has(c_letter)) {
    cycle_.z = block_.get(c_letter);
  } else if (!same_cycle) {
    fail(std::string(1, static_cast<char>(std::toupper(c_letter))) + " value unspecified in " +
         axes.plane + " plane canned cycle");
  }
  int repeats = 1;
  if (block_.has('l')) {
    repeats = static_cast<int>(std::nearbyint(block_.get('l')));
    if (repeats < 1) fail("Negative or zero l word used", block_.col('l'));
  }
  if (code == 820 || code == 860 || code == 880 || code == 890) {
    if (block_.has('p')) {
      cycle_.p = block_.get('p');
    } else if (!same_cycle) {
      fail("Dwell time P word missing with G" + std::to_string(code / 10));
    }
    if (cycle_.p < 0) fail("Negative dwell time");
  }
  if (code == 730 || code == 830) {
    if (block_.has('q')) {
      cycle_.q = block_.get('q');
    } else if (!same_cycle) {
      fail("Q word missing with G" + std::to_string(code / 10));
    }
    if (cycle_.q <= 0) fail("Q word must be positive with G" + std::to_string(code / 10));
  }
  if (modal_.feed_mode == FeedMode::inverse_time) {
    fail("Cannot use inverse time feed with canned cycle");
  }
  if (modal_.feed_rate == 0.0) fail("Cannot feed with zero feed rate");

  double old_c = cycle_.old_normal;
  double r = cycle_.r;
  double bottom = cycle_.z;
  if (modal_.incremental) {
    r += old_c;
    bottom += r;
  }
  if (r < bottom) {
    fail(std::string("R less than ") + c_letter + " in cycle in " + axes.plane + " plane");
  }
  // Moves of the cycle keep the axes outside the cycle's three where they are.
  auto move = [&](CanonKind kind, double a_value, double b_value, double c_value) {
    Pose end = pos_;
    end[ca] = a_value;
    end[cb] = b_value;
    end[static_cast<std::size_t>(axes.c)] = c_value;
    emit_straight(kind, end);
  };
  struct {
    decltype(move)& to;
    void traverse(double x, double y, double z) { to(CanonKind::straight_traverse, x, y, z); }
    void feed(double x, double y, double z) { to(CanonKind::straight_feed, x, y, z); }
  } run{move};
  if (old_c < r) {
    run.traverse(pos_[ca], pos_[cb], r);
    old_c = r;
  }
  const double clear = (!modal_.retract_r_plane && old_c > r) ? old_c : r;
  const bool switch_mode = modal_.control != MotionMode::exact_path;
  if (switch_mode) {
    CanonCommand& command = make(CanonKind::set_motion_control_mode);
    command.ivalue = static_cast<int>(MotionMode::exact_path);
    command.value = 0;
    emit(command);
  }
  double a = pos_[ca];
  double b = pos_[cb];
  // The first move across the plane stays clear of the work: at the current height, or at
  // the retract height when that is higher.
  double current_c = std::max(pos_[static_cast<std::size_t>(axes.c)], clear);
  for (int repeat = 0; repeat < repeats; ++repeat) {
    if (modal_.incremental) {
      a += block_.has(a_letter) ? block_.get(a_letter) : 0.0;
      b += block_.has(b_letter) ? block_.get(b_letter) : 0.0;
    } else {
      a = block_.has(a_letter) ? block_.get(a_letter) : a;
      b = block_.has(b_letter) ? block_.get(b_letter) : b;
    }
    run.traverse(a, b, current_c);
    if (current_c != r) run.traverse(a, b, r);
    switch (code) {
      case 810:
        run.feed(a, b, bottom);
        run.traverse(a, b, clear);
        break;
      case 820:
        run.feed(a, b, bottom);
        emit_simple(CanonKind::dwell, 0, cycle_.p);
        run.traverse(a, b, clear);
        break;
      case 850:
        run.feed(a, b, bottom);
        run.feed(a, b, r);
        if (clear != r) run.traverse(a, b, clear);
        break;
      case 860:
        run.feed(a, b, bottom);
        emit_simple(CanonKind::dwell, 0, cycle_.p);
        emit_simple(CanonKind::stop_spindle_turning);
        run.traverse(a, b, clear);
        emit_simple(modal_.spindle == SpindleDir::counterclockwise
                        ? CanonKind::start_spindle_counterclockwise
                        : CanonKind::start_spindle_clockwise);
        break;
      case 890:
        run.feed(a, b, bottom);
        emit_simple(CanonKind::dwell, 0, cycle_.p);
        run.feed(a, b, clear);
        break;
      default:
        fail("G" + std::to_string(code / 10) + " is not supported");
    }
    current_c = clear;
  }
  if (switch_mode) {
    CanonCommand& command = make(CanonKind::set_motion_control_mode);
    command.ivalue = static_cast<int>(modal_.control);
    command.value = modal_.tolerance;
    emit(command);
    if (modal_.control == MotionMode::continuous) {
      emit_simple(CanonKind::set_naivecam_tolerance, 0, modal_.naive_tolerance);
    }
  }
}

}  // namespace cncd::interp
