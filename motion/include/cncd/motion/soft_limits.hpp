// How far past an axis soft limit a position may lie and still be within it (machine units):
// rounding in offsets, unit conversions and arc geometry, far below any machine's resolution.
// The planner and the offline check of a whole program judge with the same figure, so that a
// program that passes the check (and program.open) is not refused when it runs.
#pragma once

namespace cncd::motion {

inline constexpr double kSoftLimitSlack = 1e-9;

}  // namespace cncd::motion
