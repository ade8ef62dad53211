// Where the planner loses time on a dense path, for the planner benchmark: per programmed move,
// cncd's time (from the simulation's per-move start times) against the time-optimal reference
// within P and against the planner's own segments timed with the whole path in view
// (path_reference.hpp), summed by the corner angle the move starts with, by its length, by the
// ratio of cncd's speed to the reference's and by its duration in servo periods.
#pragma once

#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"
#include "path_reference.hpp"

namespace cncd::bench {

// `moves`: the path's programmed moves, merged within `merge_tolerance` (G64 Q) as the planner
// merges them; `cncd_s`, `reference` (within P and Q) and `planned` (planned_optimal) give
// each its time, in the same order; `axis_blend_speeds` is `planned` with its blend arcs'
// speed limits raised to the axes' own (planned_optimal).
void print_diagnosis(const config::MachineConfig& machine,
                     const std::vector<motion::Segment>& moves, double merge_tolerance,
                     const std::vector<double>& cncd_s, const PathReference& reference,
                     const PathReference& planned, const PathReference& axis_blend_speeds);

}  // namespace cncd::bench
