// Plain types shared by the planner, the servo thread and their clients.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/machine_config.hpp"

namespace cncd::motion {

inline constexpr int kAxes = config::kMaxAxes;
inline constexpr int kJoints = config::kMaxJoints;

// Axis positions in machine coordinates and machine units, indexed by config::axis_index().
using AxisPose = std::array<double, kAxes>;
using JointArray = std::array<double, kJoints>;

// One programmed move as the task layer hands it to the planner: machine coordinates, machine
// units. Trivially copyable.
struct Move {
  enum class Kind : std::uint8_t { traverse, feed, arc, dwell };
  Kind kind = Kind::traverse;
  AxisPose end{};   // end point (traverse, feed, arc)
  double feed = 0;  // units/s along the path (feed, arc); traverse uses the limits
  // Arc: centre in the plane's two axes, the plane's normal axis, turns (>0 ccw, <0 cw,
  // LinuxCNC's "rotation": 1 = one ccw arc, -1 = one cw arc, 2 = one full extra ccw turn ...).
  std::array<int, 3> plane_axes{0, 1, 2};  // first, second, normal axis index (XY: 0,1,2)
  double center_first = 0;
  double center_second = 0;
  int turns = 0;
  double dwell_s = 0;  // dwell
  // Path control in force for this move (G61.1, G61, G64), which decides how its end joins
  // the next move: exact_stop always stops there; exact_path goes on at speed only into a
  // tangent move of the same kind (feed or traverse); blend also rounds line-line corners
  // with an arc that stays within `tolerance` of the corner (G64 P; 0 = the largest arc that
  // uses at most half of each line).
  enum class PathMode : std::uint8_t { exact_stop, exact_path, blend };
  PathMode path_mode = PathMode::exact_stop;
  double tolerance = 0;  // units
  // G64 Q: consecutive feed lines of the same feed whose points all lie within this of one
  // straight line are run as that line; 0 = no merging.
  double merge_tolerance = 0;  // units
  std::int32_t line = 0;       // source line of the program, 0 = none
};

}  // namespace cncd::motion
