// Speed and acceleration limits of blend arcs and fillets: the centripetal and tangential
// shares of the plane's acceleration, sized for the fastest speed the arc can be run at, and
// lowered to what the segments around it let through once both of its neighbours are known.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cncd/motion/planner.hpp"

namespace cncd::motion {

void Planner::set_blend_limits(Segment& blend, double entry_speed, double exit_speed) const {
  // Along the arc, axis i's share of the unit tangent is T_i = w cos(phi + alpha) and of the
  // unit normal (towards the centre) N_i = -w sin(phi + alpha), w = |(u_i, v_i)| its share of
  // the plane. Two bounds hold for its acceleration a_t T_i + a_n N_i: the orthogonal one,
  // sqrt(a_t^2 + a_n^2) w, and the sum of the parts' largest sizes over the sweep,
  // a_t max|T_i| + a_n max|N_i|, which on a short arc is far below the first when the
  // tangent and the normal lie along different axes (a slope's blend: the tangent along X,
  // the normal along Z). The sum bound is taken where it is the better of the two.
  double v = 1e300;
  double plane_a = 1e300;   // orthogonal bound: the plane's acceleration limit
  double normal_a = 1e300;  // the centripetal acceleration every axis allows alone
  const auto rates = kins_->rate_limits();
  std::array<double, kMaxRateLimits> max_t{}, max_n{};
  bool linear = false;
  for (int i = 0; i < 3; ++i)
    linear = linear || std::hypot(blend.blend_u[i], blend.blend_v[i]) > 1e-12;
  const double sweep = std::abs(blend.sweep);
  // Largest |cos| over [x, x + sweep].
  auto max_cos = [sweep](double x) {
    const double pi = std::numbers::pi;
    const double first_peak = std::ceil(x / pi) * pi;  // the first multiple of pi from x on
    if (first_peak <= x + sweep) return 1.0;
    return std::max(std::abs(std::cos(x)), std::abs(std::cos(x + sweep)));
  };
  // A bound (an axis, or a joint of several axes) is one more such share: its coefficients
  // against u and v.
  for (std::size_t k = 0; k < rates.size(); ++k) {
    const double u = rates[k].dot(blend.blend_u);
    const double u_across = rates[k].dot(blend.blend_v);
    const double w = std::hypot(u, u_across);
    if (w <= 1e-12) continue;
    const double alpha = std::atan2(u, u_across);
    max_t[k] = w * max_cos(alpha);
    max_n[k] = w * max_cos(alpha - std::numbers::pi / 2);
    if (max_t[k] > 1e-12) v = std::min(v, rates[k].max_velocity / max_t[k]);
    if (max_n[k] > 1e-12) normal_a = std::min(normal_a, rates[k].max_acceleration / max_n[k]);
    plane_a = std::min(plane_a, rates[k].max_acceleration / w);
  }
  if (linear && config_.max_linear_velocity > 0) v = std::min(v, config_.max_linear_velocity);
  // The speed limit and the tangential acceleration limit of the arc when its centripetal
  // part is sized for `fastest`.
  auto limits = [&](double fastest, double& cap, double& accel) {
    double v_orthogonal = v;
    double a_orthogonal = 0;
    curve_limits(fastest, blend.radius, plane_a, kBlendNormalShare, v_orthogonal, a_orthogonal);
    // The sum bound: the centripetal part takes what the fastest speed needs (at most the
    // share of what every axis allows), the tangential part what each axis has left.
    double centripetal = fastest * fastest / blend.radius;
    if (centripetal >= kBlendNormalShare * normal_a) centripetal = kBlendNormalShare * normal_a;
    const double v_sum = std::min(v, std::sqrt(centripetal * blend.radius));
    double a_sum = 1e300;
    for (std::size_t k = 0; k < rates.size(); ++k) {
      if (max_t[k] <= 1e-12) continue;
      const double left = rates[k].max_acceleration - centripetal * max_n[k];
      a_sum = std::min(a_sum, std::max(0.0, left) / max_t[k]);
    }
    // Only where it allows both as much speed and more acceleration: a blend left with little
    // tangential acceleration would slow everything that has to brake through it.
    const bool sum_better = v_sum >= v_orthogonal * (1 - 1e-12) && a_sum > a_orthogonal;
    cap = sum_better ? v_sum : v_orthogonal;
    accel = sum_better ? a_sum : a_orthogonal;
  };
  const double fastest = blend.feed > 0 ? std::min(v, blend.feed * config_.max_feed_override) : v;
  limits(fastest, blend.axis_velocity, blend.max_acceleration);
  auto set_feed_limit = [&blend] {
    blend.max_velocity =
        blend.feed > 0 ? std::min(blend.axis_velocity, blend.feed) : blend.axis_velocity;
  };
  set_feed_limit();
  // No profile within the limits of the segments around the arc enters it faster than
  // `entry_speed` or leaves it faster than `exit_speed` (each with a margin of two servo
  // periods' acceleration for the servo loop's steps), and along the arc the speed changes by
  // at most its tangential limit: at s from its start it is at most
  // sqrt(entry^2 + 2 a_t s) and sqrt(exit^2 + 2 a_t (length - s)), highest where the two meet.
  // Sizing the centripetal part for the lowest speed limit that still lets every such profile
  // through leaves the rest of the acceleration to the tangential part: every profile that
  // fitted the old limits fits the new ones, and the arc may speed up and slow down faster.
  if (!(std::min(entry_speed, exit_speed) < blend.axis_velocity)) return;
  const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
  const double entry_sq = entry_speed * entry_speed;
  const double exit_sq = exit_speed * exit_speed;
  auto lets_through = [&](double cap, double accel) {
    const double run = 2.0 * accel * blend.length;
    const double peak_sq =
        std::min({entry_sq + run, exit_sq + run, 0.5 * (entry_sq + exit_sq + run)});
    return cap >= std::sqrt(peak_sq) + 2.0 * accel * dt;
  };
  if (!lets_through(blend.axis_velocity, blend.max_acceleration)) return;
  double lo = 0;
  double hi = fastest;
  double hi_cap = blend.axis_velocity;
  double hi_accel = blend.max_acceleration;
  for (int step = 0; step < 24; ++step) {
    const double mid = 0.5 * (lo + hi);
    double cap = 0;
    double accel = 0;
    limits(mid, cap, accel);
    if (lets_through(cap, accel)) {
      hi = mid;
      hi_cap = cap;
      hi_accel = accel;
    } else {
      lo = mid;
    }
  }
  if (hi_accel <= blend.max_acceleration) return;
  blend.axis_velocity = hi_cap;
  blend.max_acceleration = hi_accel;
  set_feed_limit();
}

}  // namespace cncd::motion
