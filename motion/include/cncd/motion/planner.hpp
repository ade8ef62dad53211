// Turns programmed moves into segments whose every axis stays within its MAX_VELOCITY and
// MAX_ACCELERATION: the path limits are the tightest the axes allow along the move's direction
// (on arcs and blend arcs with the centripetal acceleration included), and [TRAJ]
// MAX_LINEAR_VELOCITY. Where a joint is no axis of its own (corexy's motors) its limits are
// kept the same way (Kinematics::rate_limits()). Non-RT: called on the task thread.
//
// The stateful side (push/flush) looks one move ahead: it holds back the newest move until the
// next one shows how the two join, and a blend arc until the junction after the move it leads
// into is known (its limits depend on how fast the path can leave it). Tangent junctions are marked
// for the servo loop to cross at speed; under G64 a line-line corner gets a tangent blend arc
// within the P tolerance, and a corner where a programmed arc meets a line or another arc in its
// plane a tangent fillet arc; every other junction stops, or is crossed slowly when it is a small
// kink (docs/motion.md).
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

// The largest coordinate (machine units or degrees) a move may have, homed or not: the bound
// the interpreter puts on offsets too (docs/motion.md).
inline constexpr double kMaxCoordinate = 1e9;

// Why `move`, from the tool tip at `start` (the part's frame), cannot run under TCP (M428): a
// probing move, or a move in step with the spindle that turns a rotary axis (with the rotaries
// still, the tip's map is a rotation and a translation, and such a move runs as the same line
// in joint space); nullopt when it can. The planner refuses these, and the program's check
// refuses them at their line before anything runs.
std::optional<std::string> tcp_refusal(const Move& move, const AxisPose& start);

class Planner {
 public:
  explicit Planner(const config::MachineConfig& config);

  // Plans `move` alone starting at `start` (it ends at rest). Returns nullopt and sets
  // `error` when the move cannot be made (a zero feed, an arc whose ends are not on one
  // circle, an end outside the soft limits of an axis in `check_limits`, a coordinate that is
  // not finite or beyond kMaxCoordinate).
  std::optional<Segment> plan(const Move& move, const AxisPose& start, bool check_limits,
                              std::string& error) const;

  // Under TCP (Move::tcp on a table-rotary machine): whether every joint stays within its
  // [JOINT_n] soft limits along `move`, planned from the tool tip at `start` (the part's
  // frame), as push() checks it. False with `error` (the joint and where) when one does not;
  // true for every other move.
  bool tcp_joints_within_limits(const Move& move, const AxisPose& start, std::string& error) const;

  // Forgets any held move and output, and starts the next move at `start`.
  void reset(const AxisPose& start);
  // Plans `move` from where the last pushed move ends. The segments that are final go to
  // output(); the move itself may be held back until the next push() or flush(). False (with
  // `error`) when the move cannot be made; nothing changes then.
  bool push(const Move& move, bool check_limits, std::string& error);
  // Releases the held move, ending at rest: call before anything that must happen at rest or
  // in order (dwells, spindle and tool events, program stops and ends, the end of what the
  // interpreter has to give now).
  void flush();
  // Whether a move is held back.
  bool holding() const {
    return held_.has_value() || merge_.has_value() || pending_blend_.has_value();
  }
  // Where the last pushed move ends.
  const AxisPose& end() const { return end_; }
  // Final segments, oldest first, for the caller to take from the front.
  std::deque<Segment>& output() { return output_; }

 private:
  // Largest share of a curve's in-plane acceleration limit for the centripetal part, the rest
  // (t = sqrt(1 - n^2)) being left for speeding up and slowing down. Programmed arcs are long
  // enough to change speed on; a blend arc is short and mostly run at the speed its curvature
  // allows: its share is of the centripetal acceleration every axis allows on its own share of
  // the normal, and what is left along the path is found axis by axis (blend_limits.cpp).
  static constexpr double kArcNormalShare = 0.8;
  static constexpr double kBlendNormalShare = 0.95;
  // Under trapezoidal profiles, where an arc below its top speed runs in pieces sized for the
  // speeds on them (emit_blend), the centripetal part may take more at the top.
  static constexpr double kBlendNormalShareTrapezoidal = 0.98;
  // A blend arc's centripetal part stops short of kBlendNormalShare where the tangential part
  // would keep less than this share of the plane's smallest acceleration limit.
  static constexpr double kBlendTangentialFloor = 0.1;
  // Under trapezoidal profiles, where an arc below its top speed runs in pieces and the
  // servo loop's backward pass brakes through whatever an arc leaves, a lower floor.
  static constexpr double kBlendTangentialFloorTrapezoidal = 0.05;
  // A curve of `radius` in a plane whose acceleration limit is `plane_a`, never faster than
  // `fastest` (in-plane speed, units/s): the centripetal part gets what `fastest` needs, at
  // most `max_normal` of the limit, and the tangential part what is left, at right angles, so
  // their sum and every axis of the plane stay within the limit. Lowers the in-plane speed
  // limit `v` where the curvature needs it and sets the in-plane tangential limit `a`.
  static void curve_limits(double fastest, double radius, double plane_a, double max_normal,
                           double& v, double& a);

  bool within_limits(const Segment& segment, std::string& error) const;
  // Path speed and acceleration limits of a line or an arc from its geometry and feed (0 for a
  // traverse), and its unit tangents at both ends.
  void set_limits(Segment& seg) const;
  static void set_directions(Segment& seg);
  // Path speed and acceleration limits of a blend arc (blend_u, blend_v and radius set).
  // `entry_speed`, `exit_speed`: bounds on the speeds at which any profile within the limits
  // of the segments before and after it can enter and leave the arc; where they keep it
  // below the arc's speed limit, the centripetal part is sized for the fastest such profile
  // and the tangential part gets the rest.
  // `top`: the centripetal part is never sized for more than this speed (a piece of an arc
  // whose limits the segments around it were planned with).
  void set_blend_limits(Segment& blend, double entry_speed = 1e300, double exit_speed = 1e300,
                        double top = 1e300) const;
  // Joins the held segment to `next` (a planned move): marks a tangent junction, or inserts
  // a blend arc (trimming both lines), or leaves a stop. Emits the held segment.
  void join(Segment& next, const Move& move);
  // G64 junctions off tangent where no blend arc fits (a line into an arc, arcs): crossed at
  // the speed whose jump in direction the axes absorb within a servo period, with both
  // segments' accelerations reduced to leave room for it.
  void kink(Segment& prev, bool prev_reserved, Segment& next);
  static constexpr double kKinkReserve = 0.1;
  // Gives up kKinkReserve of the segment's acceleration (and an arc's matching speed).
  static void reserve_for_kink(Segment& seg);
  // Takes a planned segment (of `move`) into the look-ahead: joins it to the held one and
  // holds it, or emits it.
  void take(Segment seg, const Move& move);
  // G64 Q: whether `move` (planned as `seg`) may start or extend a run of merged lines.
  bool mergeable(const Move& move, const Segment& seg) const;
  bool extends_merge(const Move& move, const Segment& seg) const;
  // Plans the merged run as one line and takes it.
  void release_merge();

  struct Held {
    Segment segment;
    Move::PathMode mode = Move::PathMode::exact_stop;
    double tolerance = 0;
    double full_length = 0;  // before any blend trimmed it
    bool traverse = false;
    bool reserved = false;  // its acceleration is already reduced for a kink
    // A bound on the speed at its start: 0 after a stop, the speed limit of the blend arc
    // before it (as it stands while that arc is held back), or what the segments before it
    // allow across a tangent junction or a kink.
    double entry_speed = 0;
    bool tcp = false;  // a piece of a TCP move (tcp_path.cpp)
  };

  // Consecutive G1 lines of the same feed whose points all lie within Q of the line from the
  // first start to the last end, merged into that line.
  struct Merge {
    Move move;  // the first move, with the last move's end
    AxisPose start{};
    std::vector<AxisPose> points;  // the ends skipped so far
    std::uint32_t moves = 0;
  };
  static constexpr std::size_t kMaxMerged = 256;

  // G64 corners where a programmed arc meets a line or another arc, both in the arc's plane
  // (no helix): a circular fillet tangent to both curves, within the held move's P of the
  // corner (P 0: as large as the shares allow), taking at most half of each move; the arcs
  // are trimmed by their start or end angle. False when no fillet fits; nothing changes then.
  // arc_blend.cpp.
  bool fillet(Held& held, Segment& next);

  // Tool centre point control (tcp_path.cpp). push() hands a Move::tcp move, and any move
  // while a TCP piece is held, to push_tcp(): the tool tip's path is planned in the part's
  // frame and cut into pieces straight in joint space, within TCP_TOLERANCE of it and short
  // enough that the turns between them fit in the joints' acceleration.
  bool push_tcp(const Move& move, bool check_limits, std::string& error);
  // A move in step with the spindle under TCP, the rotaries still: the tip's line as one line
  // in joint space, of the same length, run at rest at both ends as any such move.
  bool push_tcp_sync(const Move& move, bool check_limits, std::string& error);
  // The pieces of the tip's path `tip` (planned from the part pose of end_), in joint space,
  // for a tool `tool_length` long (Move::tool_length).
  bool tcp_pieces(const Segment& tip, double tool_length, std::vector<Segment>& pieces,
                  std::string& error) const;
  // `n` equal pieces of `tip`; the largest distance of their tool tip from the path.
  double cut_tcp(const Segment& tip, double tool_length, int n, std::vector<Segment>& pieces) const;
  // Whether the tool at `part_start` with `tool_length` stands where the joints are (end_),
  // that is whether the tool length may change there; false with `error` when not.
  bool same_joints_with_length(const AxisPose& part_start, double tool_length,
                               std::string& error) const;
  // The tool length the last TCP move was planned with (none since a move out of TCP): a
  // change of it moves the joints unless the tilting axis is at 0.
  std::optional<double> tcp_tool_length_;
  // Every piece's joints within their [JOINT_n] soft limits.
  bool tcp_within_joint_limits(const std::vector<Segment>& pieces, std::string& error) const;
  // Ends the held piece into `next` (a piece): at the speed at which the jump in every
  // joint's speed fits the share of its acceleration kept for it, or at rest.
  void tcp_join(Segment& next, Move::PathMode mode);
  static constexpr double kTcpPathShare = 0.5;   // of each joint's acceleration, along a piece
  static constexpr double kTcpJumpShare = 0.25;  // at each junction, within one servo period
  static constexpr int kMaxTcpPieces = 20000;
  static constexpr double kTcpSameJoint = 1e-6;  // units: a joint that does not move

  const config::MachineConfig& config_;
  std::shared_ptr<const Kinematics> kins_;
  // The path's jerk limit under S-curve profiles, 0 for trapezoidal ones.
  double jerk_ = 0;
  AxisPose end_{};
  std::optional<Merge> merge_;
  std::optional<Held> held_;
  bool next_reserved_ = false;   // join() reduced the next segment's limits for a kink
  double next_entry_speed_ = 0;  // a bound on the speed where the segment join() joins starts
  // Outputs of moves that went nowhere, for the next segment to set (SyncOutputs).
  SyncOutputs pending_sync_{};
  // Adds the `earlier` settings of outputs to `into`, whose own settings win.
  static void add_sync(SyncOutputs& into, const SyncOutputs& earlier);
  // Emits `prev` (`start_speed`: the bound on the speed at its start) and holds back the blend
  // arc or fillet that rounds its corner into `next`, its entry speed bounded by what prev
  // allows. The blend starts the next move, so next's outputs go with it; a prev the blend
  // used up entirely is dropped, its move count and outputs passing to the blend.
  void emit_corner(Segment& prev, double start_speed, Segment& blend, Segment& next);
  // Emits the held segment `prev` once its end junction is settled (`start_speed` as above,
  // `limit_after`: the speed limit of the segment after it) and sets next_entry_speed_ to the
  // bound on the speed at its end. The blend held back before prev goes first, its limits set
  // again now that what follows it is known: it cannot be left faster than prev lets the path
  // slow down to its end junction. `push` false: the blend after prev used it up.
  void emit_held(const Segment& prev, double start_speed, double limit_after, bool push = true);
  // Emits the blend arc or fillet `blend` (its limits final for the bounds `entry` and `exit`
  // on the speeds at its ends) in kBlendPieces pieces where those bounds keep it below its top
  // speed: each piece's centripetal part sized for the fastest speed the path can have there,
  // so the slow end of the arc keeps more of the acceleration for speeding up or slowing down.
  // Returns the speed limit of the last piece.
  double emit_blend(const Segment& blend, double entry, double exit);
  static constexpr int kBlendPieces = 4;
  // The fastest `seg` can be at one end when it is at most `bound` at the other: its speed
  // limit, or bound^2 + 2 a length, with two servo periods' acceleration as a margin for the
  // servo loop's steps.
  double reach_speed(const Segment& seg, double bound) const;
  // A blend arc or fillet, with the bound on its entry speed, held back until the corner at the
  // end of the move after it is known.
  struct PendingBlend {
    Segment segment;
    double entry_speed = 1e300;
  };
  std::optional<PendingBlend> pending_blend_;
  std::deque<Segment> output_;
};

}  // namespace cncd::motion
