// The time-optimal velocity profile the servo thread samples: shared by the path (segments)
// and by single-joint moves (homing, jogs). Internal to motion.
#pragma once

#include "cncd/drivers/rt.hpp"

namespace cncd::motion {

// Speeds closer than this are one speed, and a speed within it of 0 is rest: 1e-12 units/s
// moves a nanometre in eleven days. Every decision in motion that something has stopped (a
// hold is paused, an abort is over, a homing move has halted, a period's step ends still)
// asks at_rest(); the profiles never leave a speed in (0, kSpeedResolution] behind (braking
// to a limit lands on it exactly), so what they report as at rest reads as exactly 0.
inline constexpr double kSpeedResolution = 1e-12;

CNCD_RT constexpr bool at_rest(double v) noexcept {
  return v <= kSpeedResolution;
}

// Advances (s, v) along the time-optimal profile that reaches `length` at speed `v_end` (0 =
// at rest), limited by speed `v_max` (0 = come to a stop and hold) and acceleration `a`, for
// up to `dt` seconds. The profile is piecewise constant acceleration, so positions sampled
// from it at any times have second differences within `a`; when `v` is already too high to
// slow to `v_end` within `a` (a lowered limit), it brakes at `a` and arrives faster. Slowing
// down to a lowered `v_max` ends on it exactly, so a hold (`v_max` 0) ends with `v` exactly 0
// within v / a. Returns true when the end is reached; `dt` is then the time left over and `v`
// the arrival speed. RT-safe.
CNCD_RT bool advance_profile(double& s, double& v, double length, double v_max, double a,
                             double v_end, double& dt) noexcept;

// The same, coming to rest at `length`.
CNCD_RT inline bool advance_profile(double& s, double& v, double length, double v_max, double a,
                                    double& dt) noexcept {
  return advance_profile(s, v, length, v_max, a, 0.0, dt);
}

}  // namespace cncd::motion
