// The time-optimal reference of the planner benchmark: the least time in which the axes, each
// within its MAX_VELOCITY and MAX_ACCELERATION (and the programmed feed and [TRAJ]
// MAX_LINEAR_VELOCITY capping the path speed), follow a path from rest to rest. A phase-plane
// computation over the whole path, independent of the planner: the path speed squared x(s) on
// a grid along the path length s, capped at every point by the speed limits and by what the
// curvature leaves of the accelerations (v^2 |d2x_i/ds2| against the tangential part), then a
// backward and a forward pass in which every axis's acceleration
// |d2x_i/ds2 v^2 + dx_i/ds dv/dt| stays within its limit. Lines are solved exactly (one step
// each, a trapezoid at the end); curves on a grid fine enough that halving it changes the time
// by well under 0.5 % (the benchmark prints by how much). Trapezoidal: no jerk limit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"

namespace cncd::bench {

struct ReferenceOptions {
  // false: the path as written, where every junction off tangent is a corner the axes must
  // stop at. true: each corner between two lines is rounded by the largest circular arc that
  // passes within `tolerance` of it and takes at most half of each line (G64 P, the blend
  // cncd's planner puts there), and the path follows the arcs; other corners still stop.
  bool blend_corners = false;
  double tolerance = 0;  // G64 P (units); 0: the half-line limit alone
  // With blend_corners: consecutive feed lines of one feed whose skipped ends all lie within
  // this of the line from the run's start to its end (at most 256 skipped) are that line, as
  // the planner merges them under G64 Q (G64 P alone: Q = P); 0: no merging.
  double merge_tolerance = 0;
  // Grid along curves: every step at most this long (units) and turning at most max_turn
  // (rad); at least two steps a curve.
  double max_step = 0.02;
  double max_turn = 0.01;
  bool profile = false;  // fill PathReference::profile
};

// A point of a speed profile: the path speed v (units/s) at path length s (units, along the
// path as the reference rounds its corners) in the move `move` counts in.
struct SpeedPoint {
  double s = 0;
  double v = 0;
  std::uint32_t move = 0;
};

struct PathReference {
  double time_s = 0;
  // Per entry of the moves given: the time from the end of the move before (a blend arc into
  // it included, as Status::moves_done counts moves) to its end; dwells their time; a run of
  // merged moves counts in its last.
  std::vector<double> move_s;
  std::size_t steps = 0;            // grid steps
  std::size_t stops = 0;            // corners the path stops at (the ends not counted)
  std::size_t blends = 0;           // corners rounded
  std::vector<SpeedPoint> profile;  // with ReferenceOptions::profile
};

// `moves`: the path's programmed moves in order (lines, arcs, dwells), as the planner plans
// them alone (PlanSimOptions::on_move).
PathReference time_optimal(const config::MachineConfig& machine,
                           const std::vector<motion::Segment>& moves,
                           const ReferenceOptions& options);

// `moves` with the runs that merge within `q` (ReferenceOptions::merge_tolerance) each made one
// line; `last`: for each, the index in `moves` of the last move it stands for.
std::vector<motion::Segment> merged_path(const std::vector<motion::Segment>& moves, double q,
                                         std::vector<std::size_t>& last);

// The planner's own segments (its trimmed lines, blend arcs and arcs, with the limits it set
// on them) timed with the whole path in view: each a trapezoid within its max_velocity and
// max_acceleration, at rest where the planner ends a segment at rest, at most its
// junction_velocity where it crosses a kink, with no look-ahead window and no servo period.
// What the planner's choices allow, against which its execution is measured; per programmed
// move (`moves` of them) as Segment::moves counts them. `axis_blend_speeds`: the blend arcs'
// speed limit raised to what each axis allows on its own share of their curvature (their
// acceleration limit kept), to measure what the planner's limit on them costs.
PathReference planned_optimal(const config::MachineConfig& machine,
                              const std::vector<motion::Segment>& planned, std::size_t moves,
                              bool axis_blend_speeds = false);

}  // namespace cncd::bench
