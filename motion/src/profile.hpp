// The time-optimal rest-to-rest velocity profile the servo thread samples: shared by the path
// (segments) and by single-joint moves (homing). Internal to motion.
#pragma once

namespace cncd::motion {

// Advances (s, v) along the time-optimal profile that comes to rest exactly at `length`,
// limited by speed `v_max` (0 = come to a stop and hold) and acceleration `a`, for up to `dt`
// seconds. The profile is piecewise constant acceleration, so positions sampled from it at any
// times have second differences within `a`. Returns true when the end is reached; `dt` is then
// the time left over. RT-safe.
bool advance_profile(double& s, double& v, double length, double v_max, double a,
                     double& dt) noexcept;

}  // namespace cncd::motion
