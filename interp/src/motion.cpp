// G0/G1/G2/G3 (and G53) and the dispatch to canned cycles.
#include <cmath>
#include <numbers>

#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

bool is_canned_cycle(int code) {
  return code == 730 || code == 740 || (code >= 810 && code <= 890);
}

double straight_length(const Pose& from, const Pose& to) {
  auto sum = [&](int a, int b, int c) {
    const double da = to[static_cast<std::size_t>(a)] - from[static_cast<std::size_t>(a)];
    const double db = to[static_cast<std::size_t>(b)] - from[static_cast<std::size_t>(b)];
    const double dc = to[static_cast<std::size_t>(c)] - from[static_cast<std::size_t>(c)];
    return std::sqrt(da * da + db * db + dc * dc);
  };
  const double xyz = sum(kX, kY, kZ);
  if (xyz > 0.0) return xyz;
  const double uvw = sum(kU, kV, kW);
  if (uvw > 0.0) return uvw;
  return sum(kA, kB, kC);
}

}  // namespace

Pose Interpreter::Impl::target_from_words() const {
  Pose end = Comp::comp_program_start(*this);
  const bool machine = block_.g_code(GGroup::non_modal) == 530;
  if (machine) {
    // G53: the named axes are machine coordinates. LinuxCNC works this out in the rotated
    // frame with the G92 offset inside the rotation; the other axes stay where they are.
    const double angle = rotation_deg_ * std::numbers::pi / 180.0;
    Pose q = pos_;
    for (std::size_t axis = 0; axis < kAxes; ++axis)
      q[axis] += g92_offset_[axis];
    const double qx = q[kX] * std::cos(angle) - q[kY] * std::sin(angle);
    const double qy = q[kX] * std::sin(angle) + q[kY] * std::cos(angle);
    q[kX] = qx;
    q[kY] = qy;
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      const auto a = static_cast<std::size_t>(axis);
      if (block_.has(letter)) q[a] = block_.get(letter) - g5x_offset_[a] - tool_offset_[a];
    }
    end = q;
    end[kX] = q[kX] * std::cos(-angle) - q[kY] * std::sin(-angle);
    end[kY] = q[kX] * std::sin(-angle) + q[kY] * std::cos(-angle);
    for (std::size_t axis = 0; axis < kAxes; ++axis)
      end[axis] -= g92_offset_[axis];
    return end;
  }
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (!block_.has(letter)) continue;
    const auto a = static_cast<std::size_t>(axis);
    end[a] = modal_.incremental ? end[a] + block_.get(letter) : block_.get(letter);
  }
  if (block_.nx_polar) {
    // Numeryx g10: around the pole (I, J) at radius R and angle P (degrees).
    const double degree = std::numbers::pi / 180.0;
    end[kX] = nx_.pole_i + nx_.radius * std::cos(nx_.angle * degree);
    end[kY] = nx_.pole_j + nx_.radius * std::sin(nx_.angle * degree);
  }
  if (block_.has_polar_distance || block_.has_polar_angle) {
    // Polar words give X and Y around the origin; incremental ones add to the current
    // distance and angle.
    const double degree = std::numbers::pi / 180.0;
    const Pose start = Comp::comp_program_start(*this);
    double distance = std::hypot(start[kX], start[kY]);
    double angle = std::atan2(start[kY], start[kX]) / degree;
    if (block_.has_polar_distance) {
      distance = modal_.incremental ? distance + block_.polar_distance : block_.polar_distance;
    }
    if (block_.has_polar_angle) {
      angle = modal_.incremental ? angle + block_.polar_angle : block_.polar_angle;
    }
    end[kX] = distance * std::cos(angle * degree);
    end[kY] = distance * std::sin(angle * degree);
  }
  return end;
}

void Interpreter::Impl::emit_straight(StraightKind kind, const Pose& end) {
  if (kind == StraightKind::feed) {
    emit(StraightFeed{end});
  } else {
    emit(StraightTraverse{end});
  }
  pos_ = end;
}

// Inverse time: the move takes 1/F minutes, so its feed is length * F; LinuxCNC keeps that
// rate as the current feed.
// A move of no length gets LinuxCNC's rate of 0.1, not a rate of 0 the machine cannot run.
void Interpreter::Impl::set_inverse_time_rate(double length) {
  modal_.feed_rate = length == 0.0 ? 0.1 : length * block_.get('f');
  emit(SetFeedRate{modal_.feed_rate});
}

void Interpreter::Impl::straight(StraightKind kind, const Pose& end) {
  comp_.arc_not_allowed = false;
  if (kind == StraightKind::feed && modal_.feed_mode == FeedMode::inverse_time) {
    set_inverse_time_rate(straight_length(Comp::comp_program_start(*this), end));
  }
  if (comp_.active()) {
    Comp::comp_straight(*this, kind, end);
    return;
  }
  emit_straight(kind, end);
}

void Interpreter::Impl::do_motion() {
  const int explicit_code = block_.g_code(GGroup::motion);
  previous_motion_ = modal_.motion;
  if (explicit_code == 50 || explicit_code == 51) {
    // G5 and G5.1 move once and leave the motion mode as it was, as rs274 does.
    do_spline(explicit_code);
    return;
  }
  if (explicit_code >= 0) modal_.motion = explicit_code;
  if (explicit_code == 800) emit_comment("interpreter: motion mode set to none");
  const int non_modal = block_.g_code(GGroup::non_modal);
  if (axes_belong_elsewhere()) return;
  const int code = modal_.motion;
  bool axis_words = block_.has_polar_distance || block_.has_polar_angle;
  for (int axis = 0; axis < kAxes; ++axis)
    axis_words |= block_.has(kAxisLetters[axis]);
  if (code == 530 || code < 0 || code == 800) return;
  if (code == 52) {
    if (axis_words || explicit_code == 52) do_nurbs_point();
    return;
  }
  if (is_canned_cycle(code)) {
    if (axis_words && comp_.on()) fail("Cannot use canned cycles with cutter compensation on");
    if (axis_words) do_canned_cycle(code);
    return;
  }
  if (non_modal == 530 && code != 0 && code != 10) {
    fail("Must use g0 or g1 with g53", block_.g_column[0]);
  }
  if (non_modal == 530 && modal_.incremental)
    fail("Cannot use g53 incremental", block_.g_column[0]);
  if (is_g7x_code(code)) {
    if (explicit_code >= 0) do_g7x(code);
    return;
  }
  if (code >= 382 && code <= 385) {
    if (axis_words && comp_.on()) fail("Cannot probe with cutter radius comp on");
    if (axis_words) do_probe(code);
    return;
  }
  if (code == 330 || code == 331) {
    if (axis_words) do_spindle_synced(code);
    return;
  }
  if (code == 760) {
    if (axis_words) do_threading_cycle();
    return;
  }
  const bool arc_words = block_.has('i') || block_.has('j') || block_.has('k') || block_.has('r');
  if ((code == 20 || code == 30) && comp_.arc_not_allowed &&
      (axis_words || arc_words || explicit_code >= 0)) {
    fail("The move just after exiting cutter compensation mode must be straight, not an arc");
  }
  if ((code == 10 || code == 20 || code == 30) && !reading_g7x_profile()) {
    if (modal_.feed_mode == FeedMode::inverse_time && !block_.has('f') && axis_words) {
      fail(code == 10 ? "F word missing with inverse time g1 move"
                      : "F word missing with inverse time arc move");
    }
    if (modal_.feed_mode != FeedMode::inverse_time && modal_.feed_rate == 0.0 && axis_words) {
      fail(code == 10 ? "Cannot do g1 with zero feed rate" : "Cannot make arc with zero feed rate");
    }
    if (modal_.feed_mode == FeedMode::units_per_rev && modal_.speed == 0.0 && axis_words) {
      fail("Cannot feed with zero spindle speed in feed per rev mode");
    }
  }
  if (code == 20 || code == 30) {
    if (axis_words || arc_words || explicit_code >= 0) arc(code == 20, target_from_words());
    return;
  }
  // An explicit G0/G1 moves (possibly nowhere); a modal one only with axis words.
  if (!axis_words && explicit_code < 0) return;
  const Pose end = target_from_words();
  straight(code == 0 ? StraightKind::traverse : StraightKind::feed, end);
}

}  // namespace cncd::interp
