// Tool centre point control on a table-rotary machine (docs/kinematics.md, "TCP"). The tool
// tip's path is planned in the part's frame (its length and feed are the tip's), then cut into
// pieces that are straight in joint space: the servo loop runs them as it runs any line, each
// joint within its own limits along every piece. The tip on a piece strays from the path by
// at most [TRAJ] TCP_TOLERANCE; the joints' directions turn a little at every junction, which
// is crossed at the speed at which the jump in each joint's speed fits within a share of its
// acceleration kept for it (the rest stays for speeding up and slowing down along the pieces).
// Where the joints must move fast for little tip motion (near the C axis's singularity, a
// large swing of C at A 0 far from the axis) the feed drops, never a joint's limits.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cncd/motion/planner.hpp"
#include "cncd/motion/soft_limits.hpp"

namespace cncd::motion {
namespace {

// Joint-space rate of a piece: d(joints)/d(path length of the tip).
AxisPose rate(const Segment& piece) {
  AxisPose r{};
  if (piece.length <= 0) return r;
  for (int i = 0; i < kAxes; ++i)
    r[i] = (piece.end[i] - piece.start[i]) / piece.length;
  return r;
}

// Whether the joints go on in the same direction from piece `a` into piece `b`.
bool tangent(const Segment& a, const Segment& b) {
  double c = 0;
  for (int i = 0; i < kAxes; ++i)
    c += a.end_direction[i] * b.start_direction[i];
  return c > 1.0 - 5e-13;
}

double tip_distance(const AxisPose& a, const AxisPose& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

bool Planner::push_tcp(const Move& move, bool check_limits, std::string& error) {
  const bool tcp = move.tcp && kins_->has_tcp();
  if (!tcp) {
    // Out of TCP (M429): the held piece ends at rest, then the move is planned as any.
    flush();
    return push(move, check_limits, error);
  }
  // Where the last TCP move left the tool, in the part's frame, with the length it ran with.
  AxisPose part_start{};
  kins_->tcp_forward(end_, tcp_tool_length_.value_or(move.tool_length), part_start);
  if (auto why = tcp_refusal(move, part_start)) {
    error = *why;
    return false;
  }
  if (!same_joints_with_length(part_start, move.tool_length, error)) return false;
  if (move.spindle_sync != SpindleSync::none) return push_tcp_sync(move, check_limits, error);
  // The tip's path within the axes' soft limits, in the part's frame.
  auto tip = plan(move, part_start, check_limits, error);
  if (!tip) return false;
  tip->tcp = true;  // and so every piece cut from it
  tip->tool_length = move.tool_length;
  std::vector<Segment> pieces;
  if (tip->kind != Segment::Kind::dwell && tip->length > 0 &&
      !tcp_pieces(*tip, move.tool_length, pieces, error))
    return false;
  if (check_limits && !tcp_within_joint_limits(pieces, error)) return false;
  // Into TCP (M428): what is held back before it ends at rest.
  if (!(held_ && held_->tcp)) flush();
  tcp_tool_length_ = move.tool_length;
  if (pieces.empty()) {
    // Nothing moves (a dwell, or an end where the move starts).
    Segment rest = *tip;
    rest.start = rest.end = end_;
    take(rest, move);
    return true;
  }
  end_ = pieces.back().end;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    Segment& piece = pieces[k];
    const bool last = k + 1 == pieces.size();
    // Within the move every junction is crossed at speed; the move's own mode rules its end
    // and its start (with the mode of the move before it).
    const Move::PathMode mode = k == 0 ? move.path_mode : Move::PathMode::blend;
    if (k == 0) {
      add_sync(piece.sync, pending_sync_);
      pending_sync_ = {};
    }
    if (held_) {
      Move::PathMode join = std::min(mode, held_->mode);
      // Exact path (canned cycles) goes on at speed only into a tangent move of the same kind,
      // as out of TCP: a cycle stops at R, where its traverse meets the feed, and at the bottom.
      if (k == 0 && join == Move::PathMode::exact_path &&
          !(held_->traverse == (move.kind == Move::Kind::traverse) &&
            tangent(held_->segment, piece)))
        join = Move::PathMode::exact_stop;
      tcp_join(piece, join);
    }
    const Move::PathMode end_mode = last ? move.path_mode : Move::PathMode::blend;
    if (end_mode == Move::PathMode::exact_stop) {
      output_.push_back(piece);
      continue;
    }
    held_ =
        Held{piece, end_mode, move.tolerance, piece.length, move.kind == Move::Kind::traverse, true,
             0,     true};
  }
  return true;
}

bool Planner::push_tcp_sync(const Move& move, bool check_limits, std::string& error) {
  AxisPose part_start{};
  kins_->tcp_forward(end_, move.tool_length, part_start);
  auto tip = plan(move, part_start, check_limits, error);
  if (!tip) return false;
  // With the rotaries still the part's frame is the machine's turned and moved: the tip's line
  // is one joint-space line of the same length, and the spindle's revolutions map onto it at
  // the same distance per revolution.
  Segment line = *tip;
  kins_->tcp_inverse(tip->start, move.tool_length, line.start);
  kins_->tcp_inverse(tip->end, move.tool_length, line.end);
  line.tcp = true;
  line.tool_length = move.tool_length;
  if (line.length > 0) set_limits(line);
  if (check_limits && !tcp_within_joint_limits({line}, error)) return false;
  flush();
  tcp_tool_length_ = move.tool_length;
  // A tap goes down its line and back: the next move starts where it started.
  if (line.spindle_sync != SpindleSync::tap) end_ = line.end;
  take(line, move);
  return true;
}

std::optional<std::string> tcp_refusal(const Move& move, const AxisPose& start) {
  if (move.probe != ProbeMode::none)
    return "probing (G38.n) is not available under TCP (M428): the probe's trip point is known "
           "in the machine's frame only; M429 first";
  if (move.spindle_sync == SpindleSync::none) return std::nullopt;
  for (const int axis : {3, 4, 5}) {
    if (move.end[static_cast<std::size_t>(axis)] == start[static_cast<std::size_t>(axis)]) continue;
    const char letter = config::kAxisLetters[static_cast<std::size_t>(axis)];
    return std::string("a move in step with the spindle (G33, G33.1, rigid tapping) turns ") +
           letter + " under TCP (M428): under TCP it runs with the rotary axes held still";
  }
  return std::nullopt;
}

bool Planner::same_joints_with_length(const AxisPose& part_start, double tool_length,
                                      std::string& error) const {
  if (!tcp_tool_length_ || *tcp_tool_length_ == tool_length) return true;
  // With the tilting axis off 0 the new length puts the same tip elsewhere in the machine: the
  // joints would have to jump there, as LinuxCNC's would when its tool-offset pin changes.
  AxisPose there{};
  kins_->tcp_inverse(part_start, tool_length, there);
  for (int i = 0; i < kAxes; ++i) {
    if (std::abs(there[i] - end_[i]) <= kTcpSameJoint) continue;
    char text[240];
    std::snprintf(text, sizeof text,
                  "the tool length changes from %.4f to %.4f under TCP (M428) with the table "
                  "tilted: the joints would jump to keep the tip; change it with the tilting "
                  "axis at 0",
                  *tcp_tool_length_, tool_length);
    error = text;
    return false;
  }
  return true;
}

void Planner::tcp_join(Segment& next, Move::PathMode mode) {
  Segment prev = held_->segment;
  held_.reset();
  prev.continuous = false;
  if (mode != Move::PathMode::exact_stop) {
    // Crossing at speed v changes each joint's speed by v x the change of its rate, within
    // one servo period. Pieces at least a period long: at most two junctions fall in any
    // estimate of the acceleration, each within kTcpJumpShare of it.
    const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
    double v = std::min(prev.length, next.length) / dt;
    const AxisPose before = rate(prev);
    const AxisPose after = rate(next);
    AxisPose turn{};
    for (int i = 0; i < kAxes; ++i)
      turn[i] = after[i] - before[i];
    for (const RateLimit& limit : kins_->rate_limits()) {
      const double jump = std::abs(limit.dot(turn));
      if (jump > 1e-15) v = std::min(v, kTcpJumpShare * limit.max_acceleration * dt / jump);
    }
    // A turn that must be crossed this slowly is a corner: it stops.
    if (v > 0.01 * std::min(prev.max_velocity, next.max_velocity)) {
      prev.continuous = true;
      prev.junction_velocity = v;
    }
  }
  output_.push_back(prev);
}

double Planner::cut_tcp(const Segment& tip, double tool_length, int n,
                        std::vector<Segment>& pieces) const {
  pieces.clear();
  const double step = tip.length / n;
  AxisPose from{};
  kins_->tcp_inverse(tip.point_at(0), tool_length, from);
  double worst = 0;
  for (int k = 0; k < n; ++k) {
    const double s0 = step * k;
    const double s1 = k + 1 == n ? tip.length : step * (k + 1);
    AxisPose to{};
    kins_->tcp_inverse(k + 1 == n ? tip.end : tip.point_at(s1), tool_length, to);
    // The tip where the straight joint move puts it, against the path at the same share of
    // the way (which is no nearer to it than the path's nearest point).
    for (const double f : {0.25, 0.5, 0.75}) {
      AxisPose joints{};
      for (int i = 0; i < kAxes; ++i)
        joints[i] = from[i] + (to[i] - from[i]) * f;
      AxisPose part{};
      kins_->tcp_forward(joints, tool_length, part);
      worst = std::max(worst, tip_distance(part, tip.point_at(s0 + (s1 - s0) * f)));
    }
    Segment piece = tip;
    piece.kind = Segment::Kind::line;
    piece.start = from;
    piece.end = to;
    piece.length = s1 - s0;
    piece.moves = k + 1 == n ? tip.moves : 0;
    if (k > 0) piece.sync = {};
    set_limits(piece);
    piece.max_acceleration *= kTcpPathShare;
    pieces.push_back(piece);
    from = to;
  }
  return worst;
}

bool Planner::tcp_pieces(const Segment& tip, double tool_length, std::vector<Segment>& pieces,
                         std::string& error) const {
  const double tolerance = config_.table_rotary.tcp_tolerance;
  // The tip's error on a piece goes with the square of its length: cut finer until it fits.
  int n = 1;
  for (;;) {
    const double worst = cut_tcp(tip, tool_length, n, pieces);
    if (worst <= tolerance) break;
    const double more = std::ceil(n * 1.2 * std::sqrt(worst / tolerance));
    if (n >= kMaxTcpPieces || !std::isfinite(more)) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "the move needs more than %d pieces to keep the tool tip within "
                    "TCP_TOLERANCE %.6g",
                    kMaxTcpPieces, tolerance);
      error = text;
      return false;
    }
    n = static_cast<int>(std::min<double>(kMaxTcpPieces, std::max<double>(n + 1, more)));
  }
  if (n == 1) return true;
  // Shorter pieces turn less at each junction, so that a junction may be crossed faster, but
  // no piece is worth cutting shorter than a servo period's travel at its top speed: cut once
  // more so that the junctions allow the speed the pieces do, where that fits.
  const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
  double wanted = n;
  for (std::size_t k = 0; k + 1 < pieces.size(); ++k) {
    const Segment& a = pieces[k];
    const Segment& b = pieces[k + 1];
    const double top =
        std::min(a.max_velocity, b.max_velocity) * (a.feed > 0 ? config_.max_feed_override : 1.0);
    const AxisPose before = rate(a);
    const AxisPose after = rate(b);
    AxisPose turn{};
    for (int i = 0; i < kAxes; ++i)
      turn[i] = after[i] - before[i];
    double v = 1e300;
    for (const RateLimit& limit : kins_->rate_limits()) {
      const double jump = std::abs(limit.dot(turn));
      if (jump > 1e-15) v = std::min(v, kTcpJumpShare * limit.max_acceleration * dt / jump);
    }
    if (v >= top) continue;
    // The jump shrinks with the pieces' length; a piece no shorter than top x dt.
    const double finest = tip.length / (top * dt);
    wanted = std::max(wanted, std::min(n * top / v, finest));
  }
  const int more = static_cast<int>(std::min<double>(kMaxTcpPieces, std::ceil(wanted)));
  if (more > n) cut_tcp(tip, tool_length, more, pieces);
  return true;
}

bool Planner::tcp_joints_within_limits(const Move& move, const AxisPose& start,
                                       std::string& error) const {
  if (!move.tcp || !kins_->has_tcp()) return true;
  std::string unplanned;
  const auto tip = plan(move, start, false, unplanned);  // a move that cannot be is not ours
  if (!tip || tip->kind == Segment::Kind::dwell || tip->length <= 0) return true;
  std::vector<Segment> pieces;
  return tcp_pieces(*tip, move.tool_length, pieces, error) &&
         tcp_within_joint_limits(pieces, error);
}

bool Planner::tcp_within_joint_limits(const std::vector<Segment>& pieces,
                                      std::string& error) const {
  // Straight in joint space: their ends are their farthest points.
  const int joints = static_cast<int>(std::min<std::size_t>(config_.joints.size(), kJoints));
  for (const Segment& piece : pieces) {
    for (int j = 0; j < joints; ++j) {
      const int axis = kins_->axis_of_joint(j);
      if (axis < 0) continue;
      const auto& joint = config_.joints[static_cast<std::size_t>(j)];
      const double at = piece.end[axis];
      if (at >= joint.min_limit - kSoftLimitSlack && at <= joint.max_limit + kSoftLimitSlack)
        continue;
      char text[200];
      std::snprintf(text, sizeof text,
                    "the move takes joint %d (%c) to %.4f, outside its soft limits [%.4f, %.4f]", j,
                    config::kAxisLetters[static_cast<std::size_t>(axis)], at, joint.min_limit,
                    joint.max_limit);
      error = text;
      return false;
    }
  }
  return true;
}

}  // namespace cncd::motion
