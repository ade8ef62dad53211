// G0/G1/G2/G3 (and G53) and the dispatch to canned cycles.
#include <cmath>
#include <numbers>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

bool is_canned_cycle(int code) {
  return code == 730 || code == 740 || (code >= 810 && code <= 890);
}

struct PlaneAxes {
  int first;
  int second;
  int normal;
  char first_offset;   // center offset letter along `first`
  char second_offset;  // along `second`
};

PlaneAxes plane_axes(Plane plane) {
  switch (plane) {
    case Plane::xz:
      return {kZ, kX, kY, 'k', 'i'};
    case Plane::yz:
      return {kY, kZ, kX, 'j', 'k'};
    case Plane::xy:
    default:
      return {kX, kY, kZ, 'i', 'j'};
  }
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
  Pose end = pos_;
  const bool machine = block_.g_code(GGroup::non_modal) == 530;
  if (machine) {
    // G53: the words are machine coordinates; unspecified axes stay where they are.
    Pose target = program_to_machine(pos_);
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (block_.has(letter)) target[static_cast<std::size_t>(axis)] = block_.get(letter);
    }
    return machine_to_program(target);
  }
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (!block_.has(letter)) continue;
    const auto a = static_cast<std::size_t>(axis);
    end[a] = modal_.incremental ? pos_[a] + block_.get(letter) : block_.get(letter);
  }
  return end;
}

void Interpreter::Impl::emit_straight(CanonKind kind, const Pose& end) {
  CanonCommand& command = make(kind);
  command.pos = end;
  emit(command);
  pos_ = end;
}

void Interpreter::Impl::set_inverse_time_rate(double length) {
  emit_simple(CanonKind::set_feed_rate, 0, length * modal_.feed_rate);
}

void Interpreter::Impl::straight(CanonKind kind, const Pose& end) {
  if (kind == CanonKind::straight_feed && modal_.feed_mode == FeedMode::inverse_time) {
    set_inverse_time_rate(straight_length(pos_, end));
  }
  emit_straight(kind, end);
}

void Interpreter::Impl::do_motion() {
  const int explicit_code = block_.g_code(GGroup::motion);
  previous_motion_ = modal_.motion;
  if (explicit_code >= 0) modal_.motion = explicit_code;
  if (explicit_code == 800) emit_comment("interpreter: motion mode set to none");
  const int non_modal = block_.g_code(GGroup::non_modal);
  if (non_modal == 100 || non_modal == 280 || non_modal == 300 || non_modal == 520 ||
      non_modal == 920) {
    return;  // the axis words belonged to the non-modal code
  }
  const int code = modal_.motion;
  bool axis_words = false;
  for (int axis = 0; axis < kAxes; ++axis)
    axis_words |= block_.has(kAxisLetters[axis]);
  if (code == 530 || code < 0 || code == 800) return;
  if (is_canned_cycle(code)) {
    if (axis_words) do_canned_cycle(code);
    return;
  }
  if (non_modal == 530 && code != 0 && code != 10) {
    fail("Must use g0 or g1 with g53", block_.g_column[0]);
  }
  if (code == 10 || code == 20 || code == 30) {
    if (modal_.feed_mode == FeedMode::inverse_time && !block_.has('f') && axis_words) {
      fail(code == 10 ? "F word missing with inverse time g1 move"
                      : "F word missing with inverse time arc move");
    }
    if (modal_.feed_mode != FeedMode::inverse_time && modal_.feed_rate == 0.0 && axis_words) {
      fail(code == 10 ? "Cannot do g1 with zero feed rate" : "Cannot make arc with zero feed rate");
    }
  }
  if (code == 20 || code == 30) {
    arc(code == 20, target_from_words());
    return;
  }
  if (!axis_words) return;
  const Pose end = target_from_words();
  straight(code == 0 ? CanonKind::straight_traverse : CanonKind::straight_feed, end);
}

void Interpreter::Impl::arc(bool clockwise, const Pose& end) {
  const PlaneAxes axes = plane_axes(modal_.plane);
  const auto f = static_cast<std::size_t>(axes.first);
  const auto s = static_cast<std::size_t>(axes.second);
  const auto n = static_cast<std::size_t>(axes.normal);
  const double start1 = pos_[f];
  const double start2 = pos_[s];
  const double end1 = end[f];
  const double end2 = end[s];
  const bool radius_format = block_.has('r');
  const bool has_offsets = block_.has(axes.first_offset) || block_.has(axes.second_offset);
  const char* plane_name = modal_.plane == Plane::xy   ? "xy"
                           : modal_.plane == Plane::xz ? "xz"
                                                       : "yz";
  if (!block_.has(kAxisLetters[axes.first]) && !block_.has(kAxisLetters[axes.second]) &&
      radius_format) {
    fail(std::string("Both axes missing with ") +
         (modal_.plane == Plane::xy   ? "g17"
          : modal_.plane == Plane::xz ? "g18"
                                      : "g19") +
         " arc");
  }
  double center1 = 0;
  double center2 = 0;
  const double tolerance = modal_.units == Units::inches ? 0.0005 : 0.005;
  if (radius_format) {
    if (has_offsets) fail("Mixed radius ijk format for arc");
    const double radius = block_.get('r');
    const double d1 = end1 - start1;
    const double d2 = end2 - start2;
    const double chord = std::hypot(d1, d2);
    if (chord == 0.0) fail("Current point same as end point of arc");
    const double half = chord / 2.0;
    const double abs_radius = std::fabs(radius);
    if (abs_radius < half - tolerance) fail("Arc radius too small to reach end point");
    const double offset =
        abs_radius > half ? std::sqrt(abs_radius * abs_radius - half * half) : 0.0;
    // The center is on the right of the chord for a clockwise minor arc, on the left for a
    // counterclockwise one; a negative R asks for the major arc, i.e. the other side.
    const bool right = clockwise != (radius < 0.0);
    const double u1 = right ? d2 / chord : -d2 / chord;
    const double u2 = right ? -d1 / chord : d1 / chord;
    center1 = start1 + d1 / 2.0 + offset * u1;
    center2 = start2 + d2 / 2.0 + offset * u2;
  } else {
    if (!has_offsets) {
      fail(std::string("Neither ") + static_cast<char>(std::toupper(axes.first_offset)) + " nor " +
           static_cast<char>(std::toupper(axes.second_offset)) + " word given for arc in " +
           plane_name + " plane");
    }
    const double o1 = block_.has(axes.first_offset) ? block_.get(axes.first_offset) : 0.0;
    const double o2 = block_.has(axes.second_offset) ? block_.get(axes.second_offset) : 0.0;
    center1 = modal_.arc_incremental ? start1 + o1 : o1;
    center2 = modal_.arc_incremental ? start2 + o2 : o2;
    const double r_start = std::hypot(start1 - center1, start2 - center2);
    const double r_end = std::hypot(end1 - center1, end2 - center2);
    if (std::fabs(r_start - r_end) > tolerance && std::fabs(r_start - r_end) > 0.001 * r_start) {
      fail("Radius to end of arc differs from radius to start");
    }
  }
  int turns = 1;
  if (block_.has('p')) {
    const double p = block_.get('p');
    if (p != std::floor(p) || p < 1.0) fail("P value not an integer with arc", block_.col('p'));
    turns = static_cast<int>(p);
  }
  if (modal_.feed_mode == FeedMode::inverse_time) {
    const double radius = std::hypot(start1 - center1, start2 - center2);
    double a0 = std::atan2(start2 - center2, start1 - center1);
    double a1 = std::atan2(end2 - center2, end1 - center1);
    double sweep = clockwise ? a0 - a1 : a1 - a0;
    if (sweep <= 1e-12) sweep += 2.0 * std::numbers::pi;
    sweep += 2.0 * std::numbers::pi * (turns - 1);
    const double along = radius * sweep;
    const double height = end[n] - pos_[n];
    set_inverse_time_rate(std::hypot(along, height));
  }
  CanonCommand& command = make(CanonKind::arc_feed);
  command.first_end = end1;
  command.second_end = end2;
  command.first_axis = center1;
  command.second_axis = center2;
  command.rotation = clockwise ? -turns : turns;
  command.axis_end_point = end[n];
  command.plane = modal_.plane;
  command.pos = end;
  emit(command);
  pos_ = end;
}

}  // namespace cncd::interp
