// Distances from a point to programmed moves, for the blending tests.
#pragma once

#include "cncd/motion/types.hpp"

namespace cncd::test {

// Distance over X, Y and Z.
double xyz_distance(const motion::AxisPose& a, const motion::AxisPose& b);

// Distance over X, Y and Z from `p` to the programmed move from `from`: a line, or an arc or
// helix in XY of less than a turn.
double distance_to_move(const motion::AxisPose& p, const motion::AxisPose& from,
                        const motion::Move& move);

// A feed arc in XY to (x, y) about (cx, cy): turns 1 counter-clockwise, -1 clockwise.
motion::Move arc_to(double x, double y, double cx, double cy, int turns, double feed);

}  // namespace cncd::test
