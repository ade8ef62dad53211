// The time-optimal velocity profile the servo thread samples: shared by the path (segments)
// and by single-joint moves (homing, jogs). Internal to motion.
#pragma once

#include "cncd/drivers/rt.hpp"

namespace cncd::motion {

// Advances (s, v) along the time-optimal profile that reaches `length` at speed `v_end` (0 =
// at rest), limited by speed `v_max` (0 = come to a stop and hold) and acceleration `a`, for
// up to `dt` seconds. The profile is piecewise constant acceleration, so positions sampled
// from it at any times have second differences within `a`; when `v` is already too high to
// slow to `v_end` within `a` (a lowered limit), it brakes at `a` and arrives faster. Returns
// true when the end is reached; `dt` is then the time left over and `v` the arrival speed.
// RT-safe.
CNCD_RT bool advance_profile(double& s, double& v, double length, double v_max, double a,
                             double v_end, double& dt) noexcept;

// The same, coming to rest at `length`.
CNCD_RT inline bool advance_profile(double& s, double& v, double length, double v_max, double a,
                                    double& dt) noexcept {
  return advance_profile(s, v, length, v_max, a, 0.0, dt);
}

}  // namespace cncd::motion
