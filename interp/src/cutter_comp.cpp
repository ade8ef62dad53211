// The compensated path: entry moves, corners, arcs and the gouge checks, with LinuxCNC's
// geometry and messages.
#include "cutter_comp.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <variant>

#include "failure.hpp"

namespace cncd::interp {

constexpr double kSmall = 0.05;  // radians: corners within this count as tangent

static PlanePoint plane_of(const Pose& pose, CompAxes axes) {
  return {pose[axes.a], pose[axes.b]};
}
static Pose with_plane(Pose pose, CompAxes axes, PlanePoint p) {
  pose[axes.a] = p.a;
  pose[axes.b] = p.b;
  return pose;
}

static bool is_arc(const QueuedCanon& q) {
  return std::holds_alternative<ArcFeed>(q.command.op);
}

const QueuedCanon* Interpreter::Impl::Comp::front(const Impl& s) {
  return s.comp_.queue.empty() ? nullptr : &s.comp_.queue.front();
}

void Interpreter::Impl::Comp::set_start(Impl& s, PlanePoint p) {
  s.comp_.start = p;
  s.comp_.start_valid = true;
}

void Interpreter::Impl::Comp::enqueue_straight(Impl& s, StraightKind kind, PlanePoint dir,
                                               const Pose& end) {
  QueuedCanon q;
  q.command.line = s.current_line_;
  if (kind == StraightKind::feed) {
    q.command.op = StraightFeed{end};
  } else {
    q.command.op = StraightTraverse{end};
  }
  q.direction = dir;
  s.comp_.queue.push_back(std::move(q));
}

void Interpreter::Impl::Comp::enqueue_arc(Impl& s, double sweep, PlanePoint end, PlanePoint center,
                                          int turn, const Pose& end_pose) {
  ArcFeed arc;
  arc.plane = s.modal_.plane;
  arc.set_end(end_pose);
  arc.first_end = end.a;
  arc.second_end = end.b;
  arc.first_axis = center.a;
  arc.second_axis = center.b;
  arc.rotation = turn;
  QueuedCanon q;
  q.command.line = s.current_line_;
  q.command.op = arc;
  q.original_turn = sweep;
  s.comp_.queue.push_back(std::move(q));
}

void Interpreter::Impl::Comp::set_current(Impl& s, const Pose& end, PlanePoint tool) {
  const CompAxes axes = comp_axes(s.modal_.plane);
  s.pos_ = with_plane(end, axes, tool);
  s.comp_.program = end;
}

// The first move after G41/G42: the tool ends a radius to the side of the programmed end,
// square to the move.
void Interpreter::Impl::Comp::entry_straight(Impl& s, StraightKind kind, const Pose& end) {
  const CompAxes axes = comp_axes(s.modal_.plane);
  const PlanePoint current = plane_of(s.pos_, axes);
  const PlanePoint p = plane_of(end, axes);
  const double r = s.comp_.radius;
  if (distance(p, current) <= r) {
    fail("Length of cutter compensation entry move is not greater than the tool radius");
  }
  const double alpha = static_cast<double>(
      direction(current, p) + (s.comp_.side == CompSide::left ? kPiL / 2.0 : -kPiL / 2.0));
  const PlanePoint tool = along(p, r, alpha);
  set_start(s, current);
  enqueue_straight(s, kind, {std::cos(alpha), std::sin(alpha)}, with_plane(end, axes, tool));
  s.comp_.first_move = false;
  set_current(s, end, tool);
}

// An inside corner after an arc: where the compensated arc meets the new line's offset.
PlanePoint Interpreter::Impl::Comp::arc_line_corner(Impl& s, const ArcFeed& prev, PlanePoint op,
                                                    PlanePoint p) {
  const double r = s.comp_.radius;
  const PlanePoint center{prev.first_axis, prev.second_axis};
  const double oldrad = distance(center, {prev.first_end, prev.second_end});
  const double base = direction(op, p);
  const double theta = static_cast<double>(prev.rotation > 0 ? base + kHalfPiL : base - kHalfPiL);
  const double phi = direction(op, center);
  const bool inside = tool_inside_arc(s.comp_.side, prev.rotation);
  const double uncompensated = inside ? oldrad + r : oldrad - r;
  const double d = uncompensated * std::cos(theta - phi);
  const double l = (inside ? d - r : d + r) / oldrad;
  if (l > 1.0 || l < -1.0) {
    fail("Arc to straight motion makes a corner the compensated tool can't fit in without gouging");
  }
  const bool minus = inside == (prev.rotation > 0);
  const double angle = static_cast<double>((minus ? -std::acos(l) : std::acos(l)) + theta + kPiL);
  return along(center, oldrad, angle);
}

// Moves the plane end of every held-back move to `to` (the corner the next move found), refusing
// a move the change would reverse or lengthen past its arc (the tool would gouge), and sends
// them.
void Interpreter::Impl::Comp::comp_move_end_and_flush(Impl& s, PlanePoint to) {
  CompState& c = s.comp_;
  if (c.queue.empty()) return;
  for (QueuedCanon& q : c.queue) {
    if (auto* arc = std::get_if<ArcFeed>(&q.command.op)) {
      const PlanePoint center{arc->first_axis, arc->second_axis};
      const double r1 = distance({arc->first_end, arc->second_end}, center);
      const double r2 = distance(to, center);
      const double sweep = arc_sweep(c.start, center, arc->rotation, to);
      if (std::fabs(r1 - r2) > 0.01) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "BUG: cutter compensation has generated an invalid arc with mismatched "
                      "radii r1 %f r2 %f\n",
                      r1, r2);
        fail(text);
      }
      if (q.original_turn != 0.0 && c.start_valid &&
          std::fabs(sweep) > std::fabs(q.original_turn) + 0.001) {
        fail("Arc move in concave corner cannot be reached by the tool without gouging");
      }
      arc->first_end = to.a;
      arc->second_end = to.b;
      continue;
    }
    const bool feed = std::holds_alternative<StraightFeed>(q.command.op);
    if (!feed && !std::holds_alternative<StraightTraverse>(q.command.op)) continue;
    const double dot = q.direction.a * (to.a - c.start.a) + q.direction.b * (to.b - c.start.b);
    if (c.start_valid && dot < 0) {
      fail(feed ? "Straight feed in concave corner cannot be reached by the tool without gouging"
                : "Straight traverse in concave corner cannot be reached by the tool without "
                  "gouging");
    }
    const CompAxes axes = comp_axes(s.modal_.plane);
    Pose& end = feed ? std::get<StraightFeed>(q.command.op).end
                     : std::get<StraightTraverse>(q.command.op).end;
    end = with_plane(end, axes, to);
  }
  comp_dequeue(s);
  set_start(s, to);
}

CompAxes comp_axes(Plane plane) {
  if (plane == Plane::xz) return {kZ, kX, kY};
  return {kX, kY, kZ};
}

double arc_sweep(PlanePoint start, PlanePoint center, int turn, PlanePoint end) {
  if (turn == 0) return 0.0;
  double alpha = direction(center, start);
  double beta = direction(center, end);
  if (turn > 0) {
    if (beta <= alpha) beta = static_cast<double>(beta + 2.0L * kPiL);
    return static_cast<double>(beta - alpha + (turn - 1) * (2.0L * kPiL));
  }
  if (alpha <= beta) alpha = static_cast<double>(alpha + 2.0L * kPiL);
  return static_cast<double>(beta - alpha + (turn + 1) * (2.0L * kPiL));
}

Pose Interpreter::Impl::Comp::comp_program_start(const Impl& s) {
  Pose start = s.pos_;
  if (!s.comp_.on() || s.comp_.first_move) return start;
  const CompAxes axes = comp_axes(s.modal_.plane);
  start[axes.a] = s.comp_.program[axes.a];
  start[axes.b] = s.comp_.program[axes.b];
  return start;
}

// A lathe tool's origin is not the center of its nose radius, which compensation steers: in
// G18, by orientation (LinuxCNC's 1-8), X and Z move from the center to the tool's origin.
static void to_lathe_origin(CanonOp& op, int orientation, double r) {
  const int o = orientation;
  const double dx = (o == 2 || o == 6 || o == 1) ? -r : (o == 3 || o == 8 || o == 4) ? r : 0.0;
  const double dz = (o == 2 || o == 7 || o == 3) ? -r : (o == 1 || o == 5 || o == 4) ? r : 0.0;
  if (auto* arc = std::get_if<ArcFeed>(&op)) {
    arc->first_end += dz;
    arc->first_axis += dz;
    arc->second_end += dx;
    arc->second_axis += dx;
  } else if (auto* feed = std::get_if<StraightFeed>(&op)) {
    feed->end[kX] += dx;
    feed->end[kZ] += dz;
  } else if (auto* traverse = std::get_if<StraightTraverse>(&op)) {
    traverse->end[kX] += dx;
    traverse->end[kZ] += dz;
  }
}

void Interpreter::Impl::Comp::comp_dequeue(Impl& s) {
  s.comp_.start_valid = false;
  // Moved out first: a command sent may not find itself queued again.
  std::vector<QueuedCanon> queue;
  queue.swap(s.comp_.queue);
  const bool lathe = s.modal_.plane == Plane::xz && s.comp_.orientation != 0;
  for (QueuedCanon& q : queue) {
    if (lathe) to_lathe_origin(q.command.op, s.comp_.orientation, s.comp_.radius);
    s.send_command(q.command);
  }
}

bool Interpreter::Impl::Comp::comp_hold_back(Impl& s, const CanonCommand& command) {
  if (s.comp_.queue.empty()) return false;
  const bool held = std::visit(
      Overloaded{
          [](const SetFeedRate&) { return true; }, [](const Dwell&) { return true; },
          [](const SetFeedMode&) { return true; }, [](const MistOn&) { return true; },
          [](const MistOff&) { return true; }, [](const FloodOn&) { return true; },
          [](const FloodOff&) { return true; }, [](const StartSpindleClockwise&) { return true; },
          [](const StartSpindleCounterclockwise&) { return true; },
          [](const StopSpindleTurning&) { return true; },
          [](const SetSpindleMode&) { return true; }, [](const SetSpindleSpeed&) { return true; },
          [](const Comment&) { return true; }, [](const UserMCode&) { return true; },
          [](const OrientSpindle&) { return true; }, [](const auto&) { return false; }},
      command.op);
  if (!held) return false;
  s.comp_.queue.push_back(QueuedCanon{command, {}, 0.0});
  return true;
}

void Interpreter::Impl::Comp::comp_flush(Impl& s) {
  const CompAxes axes = comp_axes(s.modal_.plane);
  comp_move_end_and_flush(s, plane_of(s.pos_, axes));
  comp_dequeue(s);
}

void Interpreter::Impl::Comp::comp_scale(Impl& s, double factor) {
  CompState& c = s.comp_;
  c.radius *= factor;
  for (int axis = 0; axis < kAxes; ++axis) {
    if (is_linear_axis(axis)) c.program[static_cast<std::size_t>(axis)] *= factor;
  }
  for (QueuedCanon& q : c.queue) {
    // LinuxCNC scales the start once for each command held back.
    c.start.a *= factor;
    c.start.b *= factor;
    auto scale_pose = [&](Pose& pose) {
      for (int axis = 0; axis < kAxes; ++axis) {
        if (is_linear_axis(axis)) pose[static_cast<std::size_t>(axis)] *= factor;
      }
    };
    if (auto* arc = std::get_if<ArcFeed>(&q.command.op)) {
      arc->first_end *= factor;
      arc->second_end *= factor;
      arc->axis_end_point *= factor;
      arc->first_axis *= factor;
      arc->second_axis *= factor;
      for (std::size_t i = 3; i < 6; ++i)
        arc->abc_uvw[i] *= factor;
    } else if (auto* feed = std::get_if<StraightFeed>(&q.command.op)) {
      scale_pose(feed->end);
    } else if (auto* traverse = std::get_if<StraightTraverse>(&q.command.op)) {
      scale_pose(traverse->end);
    }
  }
}

void Interpreter::Impl::Comp::comp_straight(Impl& s, StraightKind kind, const Pose& end) {
  CompState& c = s.comp_;
  if (s.block_.g_code(GGroup::non_modal) == 530) fail("Cannot use g53 with cutter radius comp");
  if (c.first_move) {
    entry_straight(s, kind, end);
    return;
  }
  const CompAxes axes = comp_axes(s.modal_.plane);
  const PlanePoint current = plane_of(s.pos_, axes);
  const PlanePoint op = plane_of(c.program, axes);
  const PlanePoint p = plane_of(end, axes);
  if (p.a == op.a && p.b == op.b) {
    // Along the normal only: the tool stays where it is in the plane.
    enqueue_straight(s, kind, {0.0, 0.0}, with_plane(end, axes, current));
    set_current(s, end, current);
    return;
  }
  const bool left = c.side == CompSide::left;
  const double r = c.radius;
  double theta = direction(op, current);
  double alpha = direction(op, p);
  double beta = 0;
  if (left) {
    if (theta < alpha) theta = static_cast<double>(theta + 2.0L * kPiL);
    beta = static_cast<double>(theta - alpha - kHalfPiL);
  } else {
    if (alpha < theta) alpha = static_cast<double>(alpha + 2.0L * kPiL);
    beta = static_cast<double>(alpha - theta - kHalfPiL);
  }
  const double gamma = static_cast<double>(left ? kHalfPiL : -kHalfPiL);
  const PlanePoint tool = along(p, r, alpha + gamma);
  const PlanePoint mid = along(op, r, alpha + gamma);
  const QueuedCanon* prev = front(s);
  const bool after_arc = prev != nullptr && is_arc(*prev);
  bool concave = beta < -kSmall || beta > kPiL + kSmall;
  if (!concave && beta > kPiL - kSmall && after_arc) {
    // Leaving an arc that turned away from the tool's side, straight back along it (the top of
    // an "h"): the tool stays on the outside rather than loop around.
    const int turn = std::get<ArcFeed>(prev->command.op).rotation;
    concave = (!left && turn > 0) || (left && turn < 0);
  }
  if (!concave && beta > kSmall) {
    // An outside corner: around it on an arc (a traverse, having no arc, goes straight).
    comp_move_end_and_flush(s, current);
    if (kind == StraightKind::feed) {
      enqueue_arc(s, 0.0, mid, op, left ? -1 : 1,
                  with_plane(with_plane(end, axes, mid), axes, mid));
      std::get<ArcFeed>(c.queue.back().command.op).axis_end_point = s.pos_[axes.c];
    } else {
      Pose corner = with_plane(end, axes, mid);
      corner[axes.c] = s.pos_[axes.c];
      enqueue_straight(s, kind, {0.0, 0.0}, corner);
    }
    comp_dequeue(s);
    set_start(s, mid);
  } else if (concave) {
    if (!after_arc) {
      const double half_corner = static_cast<double>((beta + kPiL) / 2.0);
      if (half_corner == 0.0) fail("Zero degree inside corner is invalid for cutter compensation");
      const double retreat = r / std::tan(half_corner);
      comp_move_end_and_flush(s, along(current, retreat, theta + gamma));
    } else {
      comp_move_end_and_flush(s, arc_line_corner(s, std::get<ArcFeed>(prev->command.op), op, p));
    }
  } else {
    comp_dequeue(s);
    set_start(s, current);
  }
  enqueue_straight(s, kind, {p.a - op.a, p.b - op.b}, with_plane(end, axes, tool));
  set_current(s, end, tool);
}

}  // namespace cncd::interp
