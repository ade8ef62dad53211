#include "profile.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {

bool advance_profile(double& s, double& v, double length, double v_max, double a, double v_end,
                     double& dt) noexcept {
  for (int phase = 0; phase < 8 && dt > 0; ++phase) {
    const double d = length - s;
    if (d <= 1e-12) {
      s = length;
      v = std::min(v, std::max(v_end, 0.0));
      return true;
    }
    const double end_sq = v_end * v_end;
    const double stop_sq = end_sq + 2.0 * a * d;
    if (v * v >= stop_sq - 1e-9 * (1.0 + v * v) && v > v_end) {
      // On the braking curve: slow to v_end exactly at the end, or at `a` when that is not
      // enough (the limit dropped under the speed).
      const double needed = (v * v - end_sq) / (2.0 * d);
      const double brake = needed > a * (1 + 1e-6) ? a : needed;
      const double arrival = brake == needed ? v_end : std::sqrt(std::max(0.0, v * v - 2 * a * d));
      const double t_end = (v - arrival) / brake;
      if (t_end <= dt) {
        s = length;
        v = arrival;
        dt -= t_end;
        return true;
      }
      s += v * dt - 0.5 * brake * dt * dt;
      v -= brake * dt;
      dt = 0;
      return false;
    }
    double accel;
    double duration;
    if (v > v_max + kSpeedResolution) {
      accel = -a;  // slow down to the (lowered) limit
      duration = (v - v_max) / a;
    } else {
      // Within the resolution of the limit is on it: left there, a hold's 1e-15 would
      // cruise for ever, neither moving nor at rest.
      v = std::min(v, std::max(v_max, 0.0));
      const double peak = std::sqrt(0.5 * (stop_sq + v * v));
      // Below a fast v_end the end may come before the peak: accelerate up to it.
      const double target = std::min({v_max, peak, std::sqrt(v * v + 2.0 * a * d)});
      if (target > v + kSpeedResolution) {
        accel = a;
        duration = (target - v) / a;
      } else if (at_rest(v)) {
        v = 0;
        return false;  // holding at rest
      } else {
        accel = 0;  // cruise until the braking curve (or the end, below v_end)
        duration = (d - std::max(0.0, v * v - end_sq) / (2.0 * a)) / v;
      }
    }
    const double step = std::min(std::max(duration, 0.0), dt);
    s += v * step + 0.5 * accel * step * step;
    // Slowing down to a lowered limit lands on it exactly: v - a dt, with v / a a hair over
    // dt, can leave 1e-15 over, a speed at which a hold would never count as at rest.
    v = std::max(0.0, v + accel * step);
    if (accel < 0 && (step == duration || v <= v_max + kSpeedResolution)) v = std::max(v_max, 0.0);
    dt -= step;
    if (s > length) s = length;
  }
  return false;
}

}  // namespace cncd::motion
