// Geometry for the plan simulation: the speed and acceleration limits the axes set on a
// programmed move (for the lower bounds), and the distance from a point to a move's path.
#pragma once

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"

namespace cncd::pipeline {

struct MoveLimits {
  double velocity = 0;      // fastest path speed the feed and the axes allow (units/s)
  double acceleration = 0;  // fastest path acceleration the axes allow (units/s^2)
};

// From the programmed move and the axis limits alone (never from a planner's choices, such as
// blends that cut a corner short): along a line the direction is fixed; along an arc an axis is
// credited with its chord's share of the length, which no point of the arc can undercut.
MoveLimits move_limits(const config::MachineConfig& machine, const motion::Segment& segment);

// Time to cover `length` from rest to rest at most at `velocity` and `acceleration`.
double rest_to_rest_s(double length, double velocity, double acceleration);

// XYZ distance from `point` to the path of `segment` (line or arc, helices and spirals
// included: for them the point of the same angle, an upper bound off by far less than the
// pitch or the radius change).
double distance_to_path(const motion::Segment& segment, const motion::AxisPose& point);

}  // namespace cncd::pipeline
