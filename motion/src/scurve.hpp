// Jerk-limited (S-curve) kinematics along the path: how far the path needs to slow to a speed
// when its acceleration may change by at most `jerk` per second. Internal to motion; RT-safe.
#pragma once

#include "cncd/drivers/rt.hpp"

namespace cncd::motion::scurve {

// Shortest distance in which speed `v` with acceleration `a` comes down to `target` with the
// acceleration back at zero, the acceleration changing by at most `jerk` per second and never
// beyond `accel` in size: the acceleration ramps down, holds at -accel if it has to and ramps
// back to zero as the speed reaches `target`. 0 when the speed never exceeds `target` on the
// way (`a` ramped straight to zero keeps it at or below). Where ramping `a` up from below zero
// already drops the speed to `target`, the distance until it does.
CNCD_RT double brake_distance(double v, double a, double target, double accel,
                              double jerk) noexcept;

// The speed at which the path settles when its acceleration `a` is ramped to zero at `jerk`
// from speed `v`.
CNCD_RT inline double settle_speed(double v, double a, double jerk) noexcept {
  return v + (a >= 0 ? a * a : -a * a) / (2.0 * jerk);
}

// Distance, speed and acceleration after `dt` with the acceleration going linearly from `a` to
// `a_next`; a speed that would turn negative stops at zero (distance up to that instant).
struct Step {
  double distance = 0;
  double velocity = 0;
  double acceleration = 0;
};
CNCD_RT Step integrate(double v, double a, double a_next, double dt) noexcept;

}  // namespace cncd::motion::scurve
