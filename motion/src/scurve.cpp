#include "scurve.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion::scurve {
namespace {

// Distance covered in `t` from speed `v` and acceleration `a` at constant jerk `j`.
double travel(double v, double a, double j, double t) noexcept {
  return t * (v + t * (a / 2.0 + t * j / 6.0));
}

}  // namespace

double brake_distance(double v, double a, double target, double accel, double jerk) noexcept {
  target = std::max(target, 0.0);
  // Braking harder than `accel` is taken as braking at `accel` (the caller checks that it can
  // ease off in time); a higher positive acceleration ramps down through it.
  a = std::max(a, -accel);
  if (settle_speed(v, a, jerk) <= target) {
    if (a >= 0 || v <= target) return 0.0;
    // Ramping the deceleration off passes `target` on the way down: the distance until it does.
    // v + a t + jerk t^2 / 2 = target, first root.
    const double disc = std::max(0.0, a * a - 2.0 * jerk * (v - target));
    const double t = (-a - std::sqrt(disc)) / jerk;
    return travel(v, a, jerk, std::max(t, 0.0));
  }
  // The speed must drop by more than ramping `a` to zero gives: the acceleration goes down to
  // -peak (at most `accel`), holds there for `hold` seconds, and ramps back to zero.
  // Speed change: a^2 / (2 jerk) - peak^2 / jerk - peak hold = target - v.
  const double need = (v - target) + a * a / (2.0 * jerk);
  double peak = std::sqrt(need * jerk);
  double hold = 0;
  if (peak > accel) {
    peak = accel;
    hold = (need - accel * accel / jerk) / accel;
  }
  const double t1 = (a + peak) / jerk;
  const double s1 = travel(v, a, -jerk, t1);
  const double v1 = v + a * t1 - jerk * t1 * t1 / 2.0;
  const double s2 = travel(v1, -peak, 0.0, hold);
  const double v2 = v1 - peak * hold;
  const double s3 = travel(v2, -peak, jerk, peak / jerk);
  return s1 + s2 + s3;
}

Step integrate(double v, double a, double a_next, double dt) noexcept {
  const double j = (a_next - a) / dt;
  Step step{travel(v, a, j, dt), v + (a + a_next) * dt / 2.0, a_next};
  if (step.velocity >= 0) return step;
  // The speed reaches zero within the period: v + a t + j t^2 / 2 = 0, first positive root.
  double t = dt;
  if (std::abs(j) > 1e-12) {
    const double disc = std::max(0.0, a * a - 2.0 * j * v);
    const double r1 = (-a - std::sqrt(disc)) / j;
    const double r2 = (-a + std::sqrt(disc)) / j;
    t = dt;
    if (r1 >= 0 && r1 < t) t = r1;
    if (r2 >= 0 && r2 < t) t = r2;
  } else if (a < 0) {
    t = std::min(dt, -v / a);
  }
  return Step{std::max(0.0, travel(v, a, j, t)), 0.0, 0.0};
}

}  // namespace cncd::motion::scurve
