// The planner's look-ahead: holding the newest move back until the next one shows how the two
// join, marking tangent junctions and rounding G64 line-line corners with a blend arc.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cncd/motion/planner.hpp"

namespace cncd::motion {
namespace {

// Junctions within 1e-6 rad are tangent: at the path speed limits no axis changes speed by
// more than 1e-6 of the path speed at once.
constexpr double kTangentCos = 1.0 - 5e-13;
// Smaller blend arcs are not worth a segment: the corner stops instead.
constexpr double kMinBlendRadius = 1e-6;

double dot(const AxisPose& a, const AxisPose& b) {
  double sum = 0;
  for (int i = 0; i < kAxes; ++i)
    sum += a[i] * b[i];
  return sum;
}

// Whether a line's path length is its length over all axes: then a blend arc, measured over
// all axes, keeps the feed's meaning. Lines that move rotary axes along with XYZ are not
// blended.
bool euclidean(const Segment& s) {
  double sum = 0;
  for (int i = 0; i < kAxes; ++i)
    sum += (s.end[i] - s.start[i]) * (s.end[i] - s.start[i]);
  return std::abs(std::sqrt(sum) - s.length) <= 1e-9 * std::max(1.0, s.length);
}

}  // namespace

void Planner::reset(const AxisPose& start) {
  end_ = start;
  merge_.reset();
  held_.reset();
  pending_blend_.reset();
  output_.clear();
  pending_sync_ = {};
}

bool Planner::push(const Move& move, bool check_limits, std::string& error) {
  const bool tcp = move.tcp && kins_->has_tcp();
  if (!tcp) tcp_tool_length_.reset();  // out of TCP the joints are the axes, any tool
  if (tcp || (held_ && held_->tcp)) return push_tcp(move, check_limits, error);
  auto planned = plan(move, end_, check_limits, error);
  if (!planned) return false;
  const AxisPose start = end_;
  // A tap goes down its line and back: the next move starts where it started.
  end_ = planned->spindle_sync == SpindleSync::tap ? start : planned->end;
  if (merge_ && extends_merge(move, *planned)) {
    merge_->points.push_back(merge_->move.end);
    merge_->move.end = planned->end;
    ++merge_->moves;
    return true;
  }
  release_merge();
  if (mergeable(move, *planned)) {
    merge_ = Merge{move, start, {}, 1};
    merge_->move.end = planned->end;
    return true;
  }
  take(*planned, move);
  return true;
}

bool Planner::mergeable(const Move& move, const Segment& seg) const {
  return move.kind == Move::Kind::feed && !move.sync.any() && move.probe == ProbeMode::none &&
         move.spindle_sync == SpindleSync::none && move.path_mode == Move::PathMode::blend &&
         move.merge_tolerance > 0 && seg.kind == Segment::Kind::line && seg.length > 0 &&
         euclidean(seg);
}

bool Planner::extends_merge(const Move& move, const Segment& seg) const {
  const Merge& m = *merge_;
  if (!mergeable(move, seg) || move.feed != m.move.feed ||
      move.merge_tolerance != m.move.merge_tolerance || move.tolerance != m.move.tolerance ||
      m.points.size() >= kMaxMerged)
    return false;
  // Every point the merged line skips stays within Q of it, in order along it.
  AxisPose d{};
  double len_sq = 0;
  for (int i = 0; i < kAxes; ++i) {
    d[i] = seg.end[i] - m.start[i];
    len_sq += d[i] * d[i];
  }
  if (len_sq <= 0) return false;
  double last_t = 0;
  auto close = [&](const AxisPose& p) {
    double t = 0;
    for (int i = 0; i < kAxes; ++i)
      t += (p[i] - m.start[i]) * d[i];
    t /= len_sq;
    if (t < last_t || t > 1) return false;
    last_t = t;
    double off = 0;
    for (int i = 0; i < kAxes; ++i) {
      const double e = p[i] - m.start[i] - t * d[i];
      off += e * e;
    }
    return off <= m.move.merge_tolerance * m.move.merge_tolerance;
  };
  for (const auto& p : m.points) {
    if (!close(p)) return false;
  }
  return close(m.move.end);
}

void Planner::release_merge() {
  if (!merge_) return;
  const Merge m = *merge_;
  merge_.reset();
  std::string error;
  // Its parts were checked one by one; the merged line lies within their hull.
  auto seg = plan(m.move, m.start, false, error);
  if (!seg) return;
  seg->moves = m.moves;
  take(*seg, m.move);
}

void Planner::take(Segment seg, const Move& move) {
  // Outputs of a move with nothing to move are set as the next segment starts.
  add_sync(seg.sync, pending_sync_);
  pending_sync_ = {};
  if (seg.kind != Segment::Kind::dwell && seg.length == 0) {
    pending_sync_ = seg.sync;
    seg.sync = {};
    // Nothing to move: the move is done with the one before it, which keeps its junction.
    if (held_) {
      held_->segment.moves += seg.moves;
    } else {
      output_.push_back(seg);
    }
    return;
  }
  const double full_length = seg.length;
  next_reserved_ = false;
  // With nothing held, the path is at rest where the segment starts.
  next_entry_speed_ = 0.0;
  if (held_) join(seg, move);
  if (seg.kind == Segment::Kind::dwell || move.path_mode == Move::PathMode::exact_stop) {
    seg.continuous = false;
    emit_held(seg, next_entry_speed_, 0.0);
    return;
  }
  held_ = Held{seg,
               move.path_mode,
               move.tolerance,
               full_length,
               move.kind == Move::Kind::traverse,
               next_reserved_,
               next_entry_speed_};
}

void Planner::flush() {
  release_merge();
  if (held_) {
    held_->segment.continuous = false;
    emit_held(held_->segment, held_->entry_speed, 0.0);
    held_.reset();
  }
  if (pending_sync_.any()) {
    // Outputs of a last move that went nowhere: set where the path rests.
    Segment rest;
    rest.kind = Segment::Kind::dwell;
    rest.start = rest.end = end_;
    rest.sync = pending_sync_;
    rest.moves = 0;
    pending_sync_ = {};
    output_.push_back(rest);
  }
}

void Planner::add_sync(SyncOutputs& into, const SyncOutputs& earlier) {
  if (!earlier.any()) return;
  // The later settings win over the earlier ones of the same outputs.
  const std::uint32_t set = earlier.set & ~into.clear;
  const std::uint32_t clear = earlier.clear & ~into.set;
  into.set |= set;
  into.clear |= clear;
  for (int i = 0; i < kMaxAnalogIo; ++i) {
    const std::uint32_t bit = 1u << i;
    if ((earlier.analog_mask & bit) && !(into.analog_mask & bit)) {
      into.analog[static_cast<std::size_t>(i)] = earlier.analog[static_cast<std::size_t>(i)];
      into.analog_mask |= bit;
    }
  }
}

void Planner::join(Segment& next, const Move& move) {
  Held held = *held_;
  held_.reset();
  Segment& prev = held.segment;
  prev.continuous = false;
  const bool moving = next.kind != Segment::Kind::dwell;
  const double c = dot(prev.end_direction, next.start_direction);
  // The stricter of the two moves' modes rules the junction: a canned cycle (G61) is entered
  // and left as exact path even from and into G64 moves.
  const Move::PathMode mode = std::min(held.mode, move.path_mode);
  if (!moving || mode == Move::PathMode::exact_stop) {
    emit_held(prev, held.entry_speed, 0.0);
    return;
  }
  if (c > kTangentCos) {
    // Exact path (canned cycles) stops where a traverse meets a feed move, as LinuxCNC does.
    const bool same_kind = held.traverse == (move.kind == Move::Kind::traverse);
    prev.continuous = mode == Move::PathMode::blend || same_kind;
    emit_held(prev, held.entry_speed, next.axis_velocity);
    return;
  }
  if (mode != Move::PathMode::blend || prev.kind != Segment::Kind::line ||
      next.kind != Segment::Kind::line || !euclidean(prev) || !euclidean(next)) {
    // fillet() emits the trimmed held segment and the fillet arc itself.
    if (mode == Move::PathMode::blend && fillet(held, next)) return;
    if (mode == Move::PathMode::blend) kink(prev, held.reserved, next);
    emit_held(prev, held.entry_speed, next.axis_velocity);
    return;
  }
  // A tangent arc of radius R into a corner that turns by `turn` touches both lines at
  // L = R tan(turn / 2) from the corner and passes R (1 / cos(turn / 2) - 1) from it. Each
  // blend takes at most half of each line, so the blends at both ends of a line never meet.
  const double turn = std::acos(std::clamp(c, -1.0, 1.0));
  const double half = 0.5 * turn;
  double reach = 0.5 * std::min(held.full_length, next.length);
  if (held.tolerance > 0) {
    const double s = std::sin(0.5 * half);
    reach = std::min(reach, held.tolerance * std::sin(half) / (2.0 * s * s));
  }
  reach = std::min(reach, prev.length);
  const double radius = reach / std::tan(half);
  if (!(radius >= kMinBlendRadius) || !std::isfinite(radius)) {
    emit_held(prev, held.entry_speed, 0.0);
    return;
  }
  const AxisPose corner = prev.end;
  const AxisPose& d1 = prev.end_direction;
  const AxisPose& d2 = next.start_direction;
  // u: from the centre to where the arc leaves the first line, at right angles to d1 and away
  // from the turn.
  AxisPose u{};
  double u_norm = 0;
  for (int i = 0; i < kAxes; ++i) {
    u[i] = -(d2[i] - c * d1[i]);
    u_norm += u[i] * u[i];
  }
  u_norm = std::sqrt(u_norm);
  Segment blend = prev;
  blend.kind = Segment::Kind::blend;
  for (int i = 0; i < kAxes; ++i) {
    u[i] /= u_norm;
    blend.start[i] = corner[i] - reach * d1[i];
    blend.end[i] = corner[i] + reach * d2[i];
    blend.blend_center[i] = blend.start[i] - radius * u[i];
  }
  blend.blend_u = u;
  blend.blend_v = d1;
  blend.radius = radius;
  blend.sweep = turn;
  blend.length = radius * turn;
  blend.start_direction = d1;
  blend.end_direction = d2;
  blend.line = next.line;
  blend.moves = 0;
  blend.continuous = true;
  if (prev.feed > 0 && next.feed > 0) {
    blend.feed = std::min(prev.feed, next.feed);
  } else {
    blend.feed = std::max(prev.feed, next.feed);  // a traverse has none
  }
  prev.end = blend.start;
  prev.length -= reach;
  prev.continuous = true;
  next.start = blend.end;
  next.length -= reach;
  // Sized for now from the speed bound at the line's start (the speed limit of the blend arc
  // before it as that stands), accelerating all along what the arc leaves of it; emit_corner
  // lowers the bound once that arc's own limits are final.
  set_blend_limits(blend, reach_speed(prev, held.entry_speed));
  emit_corner(prev, held.entry_speed, blend, next);
}

double Planner::reach_speed(const Segment& seg, double bound) const {
  const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
  return std::min(seg.axis_velocity,
                  std::sqrt(bound * bound + 2.0 * seg.max_acceleration * seg.length)) +
         2.0 * seg.max_acceleration * dt;
}

void Planner::emit_corner(Segment& prev, double start_speed, Segment& blend, Segment& next) {
  blend.sync = next.sync;
  next.sync = {};
  const bool used_up = !(prev.length > 1e-12);
  if (used_up) {
    blend.moves += prev.moves;  // the blend took all that was left of it
    add_sync(blend.sync, prev.sync);
  }
  emit_held(prev, start_speed, blend.axis_velocity, !used_up);
  // The bound on the blend's entry speed, now that the limits before prev are final.
  const double entry = next_entry_speed_;
  Segment sized = blend;
  set_blend_limits(sized, entry);
  if (sized.axis_velocity <= blend.axis_velocity) blend = sized;
  pending_blend_ = PendingBlend{blend, entry};
  next_entry_speed_ = blend.axis_velocity;
}

void Planner::emit_held(const Segment& prev, double start_speed, double limit_after, bool push) {
  const double end = prev.continuous ? std::min(prev.junction_velocity, limit_after) : 0.0;
  if (pending_blend_) {
    // The blend before prev cannot be left faster than prev lets the path slow down to `end`
    // (reach_speed backwards).
    Segment& blend = pending_blend_->segment;
    Segment sized = blend;
    const double exit = reach_speed(prev, end);
    set_blend_limits(sized, pending_blend_->entry_speed, exit);
    // The segments after it were planned with its earlier speed limit: never above that.
    if (sized.axis_velocity <= blend.axis_velocity) blend = sized;
    start_speed = std::min(start_speed, emit_blend(blend, pending_blend_->entry_speed, exit));
    pending_blend_.reset();
  }
  if (push) output_.push_back(prev);
  next_entry_speed_ = std::min(end, reach_speed(prev, start_speed));
}

void Planner::kink(Segment& prev, bool prev_reserved, Segment& next) {
  // The direction jumps at the junction: crossing it at speed v changes each axis's speed by
  // v |d2_i - d1_i| at once, which the servo period spreads over one period. Both segments
  // give up kKinkReserve of their acceleration (and the matching part of a curve's speed
  // limit) for it; each kink may use half of that, so two kinks close together still fit.
  const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
  double v = 1e300;
  AxisPose turn{};
  for (int i = 0; i < kAxes; ++i)
    turn[i] = next.start_direction[i] - prev.end_direction[i];
  for (const RateLimit& limit : kins_->rate_limits()) {
    const double jump = std::abs(limit.dot(turn));
    if (jump <= 1e-15) continue;
    v = std::min(v, 0.5 * kKinkReserve * limit.max_acceleration * dt / jump);
  }
  // Kinks at least a period apart: at most two fall in any estimate of the acceleration.
  v = std::min({v, prev.length / dt, next.length / dt});
  // A kink that must be crossed this slowly is a corner: it stops.
  if (!(v > 0.01 * std::min(prev.max_velocity, next.max_velocity))) return;
  if (!prev_reserved) reserve_for_kink(prev);
  reserve_for_kink(next);
  next_reserved_ = true;
  prev.continuous = true;
  prev.junction_velocity = v;
}

void Planner::reserve_for_kink(Segment& seg) {
  seg.max_acceleration *= 1.0 - kKinkReserve;
  if (seg.kind == Segment::Kind::arc) seg.axis_velocity *= std::sqrt(1.0 - kKinkReserve);
  seg.max_velocity = std::min(seg.max_velocity, seg.axis_velocity);
}

}  // namespace cncd::motion
