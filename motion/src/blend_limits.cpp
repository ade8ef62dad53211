// Speed and acceleration limits of blend arcs and fillets: the centripetal and tangential parts
// of the acceleration within every axis's limit at every point of the arc, sized for the
// fastest speed the arc can be run at, and lowered to what the segments around it let through
// once both of its neighbours are known; an arc held below its top speed by those runs in
// pieces, each sized for the speeds the path can have on it.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cncd/motion/planner.hpp"

namespace cncd::motion {

namespace {

// One axis's share of a blend arc: along the arc its share of the unit tangent is
// T = w cos(psi) and of the unit normal (towards the centre) N = -w sin(psi), for psi over the
// sweep (w = |(u_i, v_i)|, its share of the plane).
struct AxisShare {
  bool moves = false;
  double limit = 0;            // the axis's acceleration limit over w
  double end_cos[2] = {0, 0};  // |cos(psi)| and |sin(psi)| at the start and the end
  double end_sin[2] = {0, 0};
  double least_sin = 0;  // the range of |sin(psi)| over the sweep
  double most_sin = 0;
};

// The most tangential acceleration a, of either sign, that leaves the axis within its limit
// while the centripetal part is anywhere from 0 to `centripetal`: at every psi,
// a |cos(psi)| + centripetal |sin(psi)| <= limit, that is a <= (limit - centripetal
// |sin(psi)|) / |cos(psi)|. Within each quarter turn that bound falls to its least,
// sqrt(limit^2 - centripetal^2), where |sin(psi)| = centripetal / limit, and rises on both
// sides of it: the least over the sweep is there, if |sin(psi)| passes that value, or at one
// of its ends. A centripetal part beyond the limit fits only where |sin(psi)| stays low.
double tangential_limit(const AxisShare& axis, double centripetal) {
  const double a = axis.limit;
  double least = 1e300;
  for (int end = 0; end < 2; ++end) {
    if (axis.end_cos[end] > 1e-15)
      least = std::min(least, (a - centripetal * axis.end_sin[end]) / axis.end_cos[end]);
  }
  const double turn = centripetal / a;
  if (turn < 1) {
    if (axis.least_sin <= turn && turn <= axis.most_sin)
      least = std::min(least, std::sqrt(a * a - centripetal * centripetal));
  } else if (axis.most_sin >= 1) {
    return 0.0;  // the centripetal part alone is too much where the normal lies along the axis
  }
  return std::max(0.0, least);
}

}  // namespace

void Planner::set_blend_limits(Segment& blend, double entry_speed, double exit_speed,
                               double top) const {
  // Along the arc the acceleration on axis i is a_t T_i + a_n N_i, a_t the tangential part (of
  // either sign, at most the arc's acceleration limit) and a_n = v^2 / r the centripetal part
  // (from 0 up to what the arc's speed limit needs). Each axis stays within its limit at every
  // point of the sweep when |a_t| |T_i| + a_n |N_i| does (tangential_limit): the exact bound,
  // which on a short arc leaves far more than the plane's limit shared between the two parts
  // when the tangent and the normal lie along different axes (a slope's blend: the tangent
  // along Z, the normal along Y).
  double v = 1e300;
  double normal_a = 1e300;  // the centripetal acceleration every axis allows alone
  double plane_a = 1e300;   // the smallest acceleration limit over the plane
  // A bound (an axis, or a joint of several axes: corexy's motors) is one more such share,
  // with its coefficients against u and v.
  const auto rates = kins_->rate_limits();
  std::array<AxisShare, kMaxRateLimits> shares{};
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
  for (std::size_t k = 0; k < rates.size(); ++k) {
    const double u = rates[k].dot(blend.blend_u);
    const double u_across = rates[k].dot(blend.blend_v);
    const double w = std::hypot(u, u_across);
    if (w <= 1e-12) continue;
    const double alpha = std::atan2(u, u_across);
    const double max_t = w * max_cos(alpha);
    const double max_n = w * max_cos(alpha - std::numbers::pi / 2);  // w max|sin(psi)|
    if (max_t > 1e-12) v = std::min(v, rates[k].max_velocity / max_t);
    if (max_n > 1e-12) normal_a = std::min(normal_a, rates[k].max_acceleration / max_n);
    AxisShare& share = shares[k];
    share.moves = true;
    share.limit = rates[k].max_acceleration / w;
    for (int end = 0; end < 2; ++end) {
      const double psi = alpha + end * sweep;
      share.end_cos[end] = std::abs(std::cos(psi));
      share.end_sin[end] = std::abs(std::sin(psi));
    }
    share.most_sin = max_cos(alpha - std::numbers::pi / 2);
    // |sin(psi)| is 0 at the multiples of pi.
    share.least_sin = std::ceil(alpha / std::numbers::pi) * std::numbers::pi <= alpha + sweep
                          ? 0.0
                          : std::min(share.end_sin[0], share.end_sin[1]);
    plane_a = std::min(plane_a, rates[k].max_acceleration / w);
  }
  if (linear && config_.max_linear_velocity > 0) v = std::min(v, config_.max_linear_velocity);
  auto tangential = [&](double centripetal) {
    double accel = 1e300;
    for (const auto& share : shares) {
      if (share.moves) accel = std::min(accel, tangential_limit(share, centripetal));
    }
    return accel;
  };
  // The most the centripetal part may take: kBlendNormalShareTrapezoidal of what every axis
  // allows (the pieces of emit_blend size an arc's slower parts for less), as long as the
  // tangential part keeps kBlendTangentialFloorTrapezoidal of the plane's smallest limit
  // (kBlendTangentialFloor under S-curve profiles; a blend left with next to no tangential
  // acceleration would slow everything that has to brake through it). Under S-curve profiles, where
  // a segment of low acceleration ahead makes the path ease its acceleration off at the jerk limit,
  // kBlendNormalShare of the plane's smallest limit, as if the two parts shared it: the tangential
  // part keeps at least the sqrt(1 - share^2) of it that sharing would leave.
  double most = jerk_ > 0 ? kBlendNormalShare * plane_a : kBlendNormalShareTrapezoidal * normal_a;
  const double keep =
      (jerk_ > 0 ? kBlendTangentialFloor : kBlendTangentialFloorTrapezoidal) * plane_a;
  if (tangential(most) < keep) {
    double lo = 0;
    for (int step = 0; step < 40; ++step) {
      const double mid = 0.5 * (lo + most);
      (tangential(mid) >= keep ? lo : most) = mid;
    }
    most = lo;
  }
  // The speed limit and the tangential acceleration limit of the arc when its centripetal
  // part is sized for `fastest`, the speed limited to what `most` allows beyond.
  auto limits = [&](double fastest, double& cap, double& accel) {
    const double centripetal = std::min(fastest * fastest / blend.radius, most);
    cap = std::min(v, std::sqrt(centripetal * blend.radius));
    accel = tangential(centripetal);
  };
  const double fastest =
      std::min(top, blend.feed > 0 ? std::min(v, blend.feed * config_.max_feed_override) : v);
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
  //
  // Under S-curve profiles a speed limit just above the speeds the path reaches still costs
  // time (the acceleration eases off before it at the jerk limit): there the arc keeps the
  // limits it has at its top speed.
  if (jerk_ > 0 || !(std::min(entry_speed, exit_speed) < blend.axis_velocity)) return;
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

double Planner::emit_blend(const Segment& blend, double entry, double exit) {
  if (jerk_ > 0 || !(std::min(entry, exit) < blend.axis_velocity) || !(blend.length > 0)) {
    output_.push_back(blend);
    return blend.axis_velocity;
  }
  // The pieces follow one another along the arc's circle, each a blend arc of its own whose
  // u and v are the arc's turned to where it starts; the arc's move count and its end junction
  // go with the last, its outputs with the first.
  constexpr int n = kBlendPieces;
  std::array<Segment, n> pieces;
  std::array<double, n> most_accel{};  // the most tangential acceleration each piece may get
  const double step = blend.sweep / n;
  auto point = [&blend](double phi) {
    AxisPose p{};
    for (int i = 0; i < kAxes; ++i)
      p[i] = blend.blend_center[i] +
             blend.radius * (std::cos(phi) * blend.blend_u[i] + std::sin(phi) * blend.blend_v[i]);
    return p;
  };
  for (int k = 0; k < n; ++k) {
    Segment& piece = pieces[static_cast<std::size_t>(k)];
    piece = blend;
    const double from = step * k;
    const double c = std::cos(from), s = std::sin(from);
    for (int i = 0; i < kAxes; ++i) {
      piece.blend_u[i] = c * blend.blend_u[i] + s * blend.blend_v[i];
      piece.blend_v[i] = -s * blend.blend_u[i] + c * blend.blend_v[i];
    }
    piece.sweep = step;
    piece.length = blend.length / n;
    piece.start = k == 0 ? blend.start : pieces[static_cast<std::size_t>(k) - 1].end;
    piece.end = k == n - 1 ? blend.end : point(step * (k + 1));
    piece.start_direction =
        k == 0 ? blend.start_direction : pieces[static_cast<std::size_t>(k) - 1].end_direction;
    for (int i = 0; i < kAxes; ++i)
      piece.end_direction[i] =
          -std::sin(step) * piece.blend_u[i] + std::cos(step) * piece.blend_v[i];
    if (k == n - 1) piece.end_direction = blend.end_direction;
    piece.moves = k == n - 1 ? blend.moves : 0;
    piece.continuous = k == n - 1 ? blend.continuous : true;
    if (k > 0) piece.sync = {};
    // With no centripetal part all of the acceleration is left along the path.
    Segment crawl = piece;
    set_blend_limits(crawl, 1e300, 1e300, 0.0);
    most_accel[static_cast<std::size_t>(k)] =
        std::max(crawl.max_acceleration, blend.max_acceleration);
  }
  const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
  double bound_in = entry;
  for (int k = 0; k < n; ++k) {
    Segment& piece = pieces[static_cast<std::size_t>(k)];
    // No profile leaves the piece faster than the rest of the arc lets the path slow down to
    // `exit`, at the most acceleration each piece after it may get.
    double run = 0, margin = 0;
    for (int j = k + 1; j < n; ++j) {
      run += 2.0 * most_accel[static_cast<std::size_t>(j)] * piece.length;
      margin = std::max(margin, 2.0 * most_accel[static_cast<std::size_t>(j)] * dt);
    }
    const double bound_out = k == n - 1 ? exit : std::sqrt(exit * exit + run) + margin;
    Segment sized = piece;
    // Never above the arc's speed limit, which the segments around it were planned with.
    set_blend_limits(sized, bound_in, bound_out, blend.axis_velocity);
    if (sized.max_acceleration >= blend.max_acceleration) piece = sized;
    bound_in = reach_speed(piece, bound_in);
    output_.push_back(piece);
  }
  return pieces[n - 1].axis_velocity;
}

}  // namespace cncd::motion
