// The planner benchmark's references for geometries other than the planner's, all within the
// program's G64 P of the programmed path: what a path that spans several short moves could
// gain over corner blends alone (path_reference.hpp times them).
//
// Smoothed: the vertices of every run of feed lines are moved, each at most `shift` from where
// it was programmed, towards a smoother sequence (a bending-energy flow: every step moves a
// vertex against the second difference of the vertices' second differences, across the path
// only, then back within `shift` of its programmed place); the moved lines are then blended
// within the rest of the tolerance by the reference's corner arcs. Every point of a moved line
// lies within `shift` of the programmed line it replaces (it is the programmed point at the
// same fraction plus a mean of two moves of at most `shift`), and every point of a blend arc
// within the blend's tolerance of the moved lines: the path stays within shift + blend
// tolerance of the programmed one.
#pragma once

#include <cstddef>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"

namespace cncd::bench {

struct SmoothOptions {
  double shift = 0;      // how far a vertex may move (units)
  int iterations = 400;  // steps of the flow
  double rate = 0.2;     // of a step (stable below 0.25)
};

// `moves` with the vertices inside each run of feed lines of one feed (connected, every line's
// path length its length over all axes) moved; the ends of every run, and every other move,
// stay. Same moves in the same order (the line count and what each completes unchanged).
std::vector<motion::Segment> smoothed_lines(const std::vector<motion::Segment>& moves,
                                            const SmoothOptions& options);

// The largest distance from a point of a line of `path` to the programmed line of `programmed`
// it replaces (same count, one to one) or its `window` neighbours each side, sampled every
// `step` along each: a measured figure, exact to within step / 2 (the distance is 1-Lipschitz
// along a line).
double polyline_deviation(const std::vector<motion::Segment>& programmed,
                          const std::vector<motion::Segment>& path, double step, int window = 1);

// Prints the references within P of a dense path (`moves`, G64 `tolerance` P, feed-limited
// `bound_s`): smoothed (shift P/2, blends within P/2), merged within P/2 and blended within P/2
// (the merge and the blends of the planner, their sum within P), and the reference within P, Q
// with P and Q both 2, 4 and 10 times the program's (how the least time falls with the
// tolerance).
void print_smoothed(const config::MachineConfig& machine, const std::vector<motion::Segment>& moves,
                    double tolerance, double merge_tolerance, double bound_s);

}  // namespace cncd::bench
