// Arcs under cutter radius compensation: the entry arc, the offset arc, and the corner before
// it (an arc around an outside corner, the meeting point in an inside one).
#include <cmath>
#include <numbers>
#include <variant>

#include "cutter_comp.hpp"
#include "failure.hpp"

namespace cncd::interp {

constexpr double kSmall = 0.05;
constexpr double kEqual = 1e-6;
constexpr double kArcToleranceMm = 0.02 * std::numbers::sqrt2;
constexpr double kArcToleranceInch = kArcToleranceMm / 10.0;

static PlanePoint plane_of(const Pose& pose, CompAxes axes) {
  return {pose[axes.a], pose[axes.b]};
}

constexpr const char* kToolTooBig = "Tool radius not less than arc radius with comp";

// The first arc after G41/G42 starts where the tool is and ends a radius off the programmed
// end; its center moves so that both ends stay on one circle.
void Interpreter::Impl::Comp::entry_arc(Impl& s, bool clockwise, const Pose& end, int turns) {
  const CompAxes axes = comp_axes(s.modal_.plane);
  const CompState& c = s.comp_;
  const PlanePoint current = plane_of(s.pos_, axes);
  PlanePoint p = plane_of(end, axes);
  const int turn = clockwise ? -turns : turns;
  const bool inside = tool_inside_arc(c.side, turn);
  if (distance(p, current) <= c.radius) {
    fail("Radius of cutter compensation entry arc is not greater than the tool radius");
  }
  if (s.block_.has('r') && std::fabs(s.block_.get('r')) <= c.radius && inside) fail(kToolTooBig);
  PlanePoint center;
  s.arc_center(clockwise, current, p, center.a, center.b);
  if (!s.block_.has('r') && distance(center, current) <= c.radius && inside) fail(kToolTooBig);
  if (s.modal_.feed_mode == FeedMode::inverse_time) {
    s.arc_feed_rate(clockwise, turns, s.pos_, center, end);
  }
  const double gamma = inside ? direction(p, center) : direction(center, p);
  s.comp_.first_move = false;
  const PlanePoint tool = along(p, c.radius, gamma);
  const double half_chord = distance(current, tool) / 2.0;
  const double to_center = direction(tool, center);
  const double corner = direction(tool, current) - to_center;
  if (std::fabs(std::cos(corner)) < kEqual) fail(kToolTooBig);
  const PlanePoint new_center = along(tool, half_chord / std::cos(corner), to_center);
  const double tolerance = s.modal_.units == Units::inches ? kArcToleranceInch : kArcToleranceMm;
  if (std::fabs(distance(new_center, tool) - distance(new_center, current)) > tolerance) {
    fail("Bug in tool radius comp");
  }
  if (c.orientation != 0 && c.orientation != 9) {
    Pose start = end;
    start[axes.a] = current.a;
    start[axes.b] = current.b;
    start[axes.c] = s.pos_[axes.c];
    QueuedCanon q;
    q.command.line = s.current_line_;
    q.command.op = StraightFeed{start};
    s.comp_.queue.push_back(std::move(q));
    s.comp_.start = current;
    s.comp_.start_valid = true;
  }
  enqueue_arc(s, arc_sweep(current, new_center, turn, tool), tool, new_center, turn, end);
  set_current(s, end, tool);
}

void Interpreter::Impl::Comp::comp_arc(Impl& s, bool clockwise, const Pose& end, int turns) {
  if (s.comp_.first_move) {
    entry_arc(s, clockwise, end, turns);
    return;
  }
  CompState& c = s.comp_;
  const CompAxes axes = comp_axes(s.modal_.plane);
  const PlanePoint op = plane_of(c.program, axes);
  const PlanePoint current = plane_of(s.pos_, axes);
  const PlanePoint p = plane_of(end, axes);
  PlanePoint center;
  s.arc_center(clockwise, op, p, center.a, center.b);
  const Pose program_start = comp_program_start(s);
  if (s.modal_.feed_mode == FeedMode::inverse_time) {
    s.arc_feed_rate(clockwise, turns, program_start, center, end);
  }
  const bool left = c.side == CompSide::left;
  const int turn = clockwise ? -turns : turns;
  const double r = c.radius;
  const double arc_radius = distance(center, p);
  const double theta = static_cast<double>(direction(op, current) + (left ? -kHalfPiL : kHalfPiL));
  double delta = direction(op, center);
  const double alpha = static_cast<double>(clockwise ? delta + kHalfPiL : delta - kHalfPiL);
  double beta = left ? theta - alpha : alpha - theta;
  if (beta > 1.5L * kPiL) {
    beta = static_cast<double>(beta - 2.0L * kPiL);
  } else if (beta < -kHalfPiL) {
    beta = static_cast<double>(beta + 2.0L * kPiL);
  }
  const bool inside = tool_inside_arc(c.side, turn);
  double gamma = 0;
  if (inside) {
    gamma = direction(p, center);
    if (arc_radius <= r) fail(kToolTooBig);
  } else {
    gamma = direction(center, p);
    delta = static_cast<double>(delta + kPiL);
  }
  const PlanePoint tool = along(p, r, gamma);
  const double sweep = arc_sweep(op, center, turn, p);
  if (beta < -kSmall || beta > kPiL + kSmall || (std::fabs(beta - kPiL) < kSmall && !inside)) {
    // An inside corner (or the tangent top of an "m" or "h"): where the two offset paths meet.
    const QueuedCanon* prev = c.queue.empty() ? nullptr : &c.queue.front();
    PlanePoint mid;
    if (prev == nullptr || !std::holds_alternative<ArcFeed>(prev->command.op)) {
      const double cy = static_cast<double>(arc_radius * std::sin(beta - kHalfPiL));
      const double from_center = inside ? arc_radius - r : arc_radius + r;
      const double l = (inside ? cy + r : cy - r) / from_center;
      if (l > 1.0 || l < -1.0) {
        fail("Arc move in concave corner cannot be reached by the tool without gouging");
      }
      double angle = 0;
      if (inside) {
        angle = turn > 0 ? theta + std::asin(l) : theta - std::asin(l);
      } else {
        angle = static_cast<double>(turn > 0 ? theta + kPiL - std::asin(l)
                                             : theta + kPiL + std::asin(l));
      }
      mid = along(center, from_center, angle);
    } else {
      const ArcFeed& before = std::get<ArcFeed>(prev->command.op);
      const PlanePoint old_center{before.first_axis, before.second_axis};
      const double oldrad = distance(old_center, {before.first_end, before.second_end});
      const double newrad = inside ? arc_radius - r : arc_radius + r;
      const double centers = distance(old_center, center);
      if (oldrad == 0.0 || centers == 0.0) {
        fail("Arc to arc motion is invalid because the arcs have the same center");
      }
      const double a =
          (oldrad * oldrad + centers * centers - newrad * newrad) / (2.0 * oldrad * centers);
      if (a > 1.0 || a < -1.0) {
        fail("Arc to arc motion makes a corner the compensated tool can't fit in without gouging");
      }
      const double pullback = std::acos(a);
      const double between = direction(old_center, center);
      const bool plus = tool_inside_arc(c.side, before.rotation) == (turn > 0);
      mid = along(old_center, oldrad, plus ? between + pullback : between - pullback);
    }
    comp_move_end_and_flush(s, mid);
  } else if (beta > kSmall) {
    // An outside corner: an arc around the programmed corner first.
    const PlanePoint mid = along(op, r, delta);
    comp_dequeue(s);
    Pose corner = end;
    corner[axes.c] = s.pos_[axes.c];
    enqueue_arc(s, 0.0, mid, op, left ? -1 : 1, corner);
    comp_dequeue(s);
    c.start = mid;
    c.start_valid = true;
  } else {
    comp_dequeue(s);
    c.start = current;
    c.start_valid = true;
  }
  enqueue_arc(s, sweep, tool, center, turn, end);
  set_current(s, end, tool);
}

}  // namespace cncd::interp
