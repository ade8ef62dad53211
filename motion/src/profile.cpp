#include "profile.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {

bool advance_profile(double& s, double& v, double length, double v_max, double a,
                     double& dt) noexcept {
  for (int phase = 0; phase < 8 && dt > 0; ++phase) {
    const double d = length - s;
    if (d <= 1e-12) {
      s = length;
      v = 0;
      return true;
    }
    const double stop_sq = 2.0 * a * d;
    if (v * v >= stop_sq - 1e-9 * (1.0 + v * v)) {
      // On the braking curve: brake to rest exactly at the end.
      if (v <= 0) {
        s = length;
        return true;
      }
      const double brake = v * v / (2.0 * d);
      const double t_stop = v / brake;
      if (t_stop <= dt) {
        s = length;
        v = 0;
        dt -= t_stop;
        return true;
      }
      s += v * dt - 0.5 * brake * dt * dt;
      v -= brake * dt;
      dt = 0;
      return false;
    }
    double accel;
    double duration;
    if (v > v_max + 1e-12) {
      accel = -a;  // slow down to the (lowered) limit
      duration = (v - v_max) / a;
    } else {
      const double peak = std::sqrt(0.5 * (stop_sq + v * v));
      const double target = std::min(v_max, peak);
      if (target > v + 1e-12) {
        accel = a;
        duration = (target - v) / a;
      } else if (v <= 0) {
        return false;  // holding at rest
      } else {
        accel = 0;  // cruise until the braking curve
        duration = (d - v * v / (2.0 * a)) / v;
      }
    }
    const double step = std::min(std::max(duration, 0.0), dt);
    s += v * step + 0.5 * accel * step * step;
    v = std::max(0.0, v + accel * step);
    dt -= step;
    if (s > length) s = length;
  }
  return false;
}

}  // namespace cncd::motion
