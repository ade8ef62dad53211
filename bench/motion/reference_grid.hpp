// The grid of the time-optimal reference (path_reference.cpp): the path as steps, lines whole
// and curves in short pieces, and the backward and forward passes over the speed squared at
// their ends. Internal to the planner benchmark.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"
#include "path_reference.hpp"

namespace cncd::bench::reference {

using motion::AxisPose;
using motion::kAxes;
using motion::Segment;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kTiny = 1e-12;

// center + r(s) (cos th(s) u + sin th(s) v) + s lin, with r = r0 + dr s and th = th0 + w s:
// a programmed arc (a helix, a spiral) or a blend arc, by path length s.
struct Curve {
  AxisPose center{}, u{}, v{}, lin{};
  double r0 = 0, dr = 0, th0 = 0, w = 0;
  // Tangent dx/ds and curvature d2x/ds2 at s.
  void at(double s, AxisPose& t, AxisPose& c) const {
    const double r = r0 + dr * s;
    const double th = th0 + w * s;
    const double cs = std::cos(th), sn = std::sin(th);
    for (int i = 0; i < kAxes; ++i) {
      const double radial = cs * u[i] + sn * v[i];
      const double across = -sn * u[i] + cs * v[i];
      t[i] = dr * radial + r * w * across + lin[i];
      c[i] = 2 * dr * w * across - r * w * w * radial;
    }
  }
};

// Per axis on a curved step: A / |dx/ds| and sigma / |dx/ds| (sigma = d2x/ds2 sign(dx/ds)),
// the path accelerations u it allows at speed squared x being within (-A - sigma x) / |t| and
// (A - sigma x) / |t|; a_t infinite where the axis moves across the path alone (it caps x).
struct Coef {
  double a_t = kInf;
  double s_t = 0;
};

struct Step {
  double length = 0;
  double cap = kInf;     // highest speed squared along it
  double accel = kInf;   // a line's highest path acceleration
  std::size_t coef = 0;  // a curve's Coef, one per present axis from here
  bool curved = false;
  std::uint32_t move = 0;
};

class Grid {
 public:
  Grid(const config::MachineConfig& machine, const ReferenceOptions& options)
      : options_(options), linear_v_(machine.max_linear_velocity) {
    for (int i = 0; i < kAxes; ++i) {
      const auto& axis = machine.axes[static_cast<std::size_t>(i)];
      if (!axis.present) continue;
      axes_.push_back(i);
      v_[static_cast<std::size_t>(i)] = axis.max_velocity;
      a_[static_cast<std::size_t>(i)] = axis.max_acceleration;
    }
  }

  // `length` of the line `move` (what the blends at its ends leave of it).
  void line(const Segment& move, double length, std::uint32_t index) {
    if (length <= 0) return;
    AxisPose t{};
    for (int i = 0; i < kAxes; ++i)
      t[i] = (move.end[i] - move.start[i]) / move.length;
    Step step{length, cap(t, AxisPose{}, move.feed), kInf, 0, false, index};
    for (int i : axes_) {
      const double share = std::abs(t[i]);
      if (share > kTiny) step.accel = std::min(step.accel, a(i) / share);
    }
    steps_.push_back(step);
  }

  void curve(const Curve& curve, double length, double turn, double feed, std::uint32_t move) {
    const double by_length = std::ceil(length / options_.max_step);
    const double by_turn = std::ceil(std::abs(turn) / options_.max_turn);
    const auto n = static_cast<std::size_t>(std::max({2.0, by_length, by_turn}));
    const double ds = length / static_cast<double>(n);
    AxisPose t{}, c{};
    for (std::size_t k = 0; k < n; ++k) {
      curve.at((static_cast<double>(k) + 0.5) * ds, t, c);
      steps_.push_back({ds, cap(t, c, feed), kInf, coefs_.size(), true, move});
      for (int i : axes_) {
        const double share = std::abs(t[i]);
        const double sigma = t[i] >= 0 ? c[i] : -c[i];
        coefs_.push_back(share > kTiny ? Coef{a(i) / share, sigma / share} : Coef{});
      }
    }
  }

  // A segment with its own limits: the path speed squared `cap` and acceleration `accel`.
  void fixed(double length, double cap, double accel, std::uint32_t index) {
    if (length > 0) steps_.push_back({length, cap, accel, 0, false, index});
  }

  // The path speed squared at the current node at most `cap` (0: the path stops there).
  void limit(double cap) { limits_.emplace_back(steps_.size(), cap); }
  void stop() { limit(0); }

  // The passes; adds each step's time to its move's.
  std::size_t solve(std::vector<double>& move_s) const {
    const std::vector<double> x = speeds();
    for (std::size_t k = 0; k < steps_.size(); ++k)
      move_s[steps_[k].move] += time(steps_[k], x[k], x[k + 1]);
    return steps_.size();
  }

  // The speed along the path after the passes: a point at every node, and on a line's ramps
  // enough points between that the speed reads straight between them.
  std::vector<SpeedPoint> profile() const {
    const std::vector<double> x = speeds();
    std::vector<SpeedPoint> out;
    double s = 0;
    if (!steps_.empty()) out.push_back({0, 0, steps_.front().move});
    for (std::size_t k = 0; k < steps_.size(); ++k) {
      const Step& step = steps_[k];
      if (!step.curved && step.accel < kInf) ramps(step, s, x[k], x[k + 1], out);
      s += step.length;
      out.push_back({s, std::sqrt(x[k + 1]), step.move});
    }
    return out;
  }

 private:
  // Speed squared at every node: at rest at both ends, within the caps and the limits, then
  // the backward and forward passes.
  std::vector<double> speeds() const {
    const std::size_t n = steps_.size();
    std::vector<double> x;
    if (n == 0) return x;
    x.reserve(n + 1);
    x.push_back(0);
    for (std::size_t k = 1; k < n; ++k)
      x.push_back(std::min(steps_[k - 1].cap, steps_[k].cap));
    x.push_back(0);
    for (const auto& [node, highest] : limits_)
      x[node] = std::min(x[node], highest);
    for (std::size_t k = n; k-- > 0;)
      x[k] = std::min(x[k], backward(steps_[k], x[k + 1]));
    for (std::size_t k = 0; k < n; ++k)
      x[k + 1] = std::min(x[k + 1], forward(steps_[k], x[k]));
    return x;
  }

  // The inside of a line's step from s0 (speeds squared x0, x1 at its ends): up at its
  // acceleration to the peak, at the peak, down to x1 (x linear in s on the ramps).
  static void ramps(const Step& step, double s0, double x0, double x1,
                    std::vector<SpeedPoint>& out) {
    constexpr int kPoints = 8;  // a ramp's
    const double a = step.accel;
    const double peak = std::max({std::min(step.cap, 0.5 * (x0 + x1) + a * step.length), x0, x1});
    const double up = (peak - x0) / (2 * a), down = (peak - x1) / (2 * a);
    for (int k = 1; k <= kPoints && up > 0; ++k) {
      const double d = up * k / kPoints;
      out.push_back({s0 + d, std::sqrt(x0 + 2 * a * d), step.move});
    }
    const double from = s0 + step.length - down;
    for (int k = 0; k < kPoints && down > 0; ++k) {
      const double d = down * k / kPoints;
      out.push_back({from + d, std::sqrt(peak - 2 * a * d), step.move});
    }
  }

  double a(int i) const { return a_[static_cast<std::size_t>(i)]; }

  // Highest speed squared at a point of tangent t and curvature c: the feed, the axes'
  // velocities and, for every two axes i and j, what leaves a path acceleration within both
  // of their ranges (for one axis that moves across the path alone: |c| x <= A).
  double cap(const AxisPose& t, const AxisPose& c, double feed) const {
    double x = feed > 0 ? feed * feed : kInf;
    const double xyz = std::hypot(t[0], t[1], t[2]);
    if (linear_v_ > 0 && xyz > kTiny) x = std::min(x, linear_v_ * linear_v_ / (xyz * xyz));
    for (int i : axes_) {
      const double ti = std::abs(t[i]);
      if (ti <= kTiny) {
        if (std::abs(c[i]) > kTiny) x = std::min(x, a(i) / std::abs(c[i]));
        continue;
      }
      const double vi = v_[static_cast<std::size_t>(i)] / ti;
      x = std::min(x, vi * vi);
      const double si = (t[i] >= 0 ? c[i] : -c[i]) / ti;
      for (int j : axes_) {
        const double tj = std::abs(t[j]);
        if (j == i || tj <= kTiny) continue;
        const double k = si - (t[j] >= 0 ? c[j] : -c[j]) / tj;
        if (k < 0) x = std::min(x, (a(i) / ti + a(j) / tj) / -k);
      }
    }
    return x;
  }

  // Highest speed squared at the step's end, from x at its start.
  double forward(const Step& step, double x) const {
    if (!step.curved) return x + 2 * step.accel * step.length;
    double u = kInf;
    for (std::size_t k = 0; k < axes_.size(); ++k) {
      const Coef& q = coefs_[step.coef + k];
      if (q.a_t < kInf) u = std::min(u, q.a_t - q.s_t * x);
    }
    return u < kInf ? std::max(0.0, x + 2 * step.length * u) : kInf;
  }

  // Highest speed squared at the step's start from which it can end at x_end.
  double backward(const Step& step, double x_end) const {
    if (!step.curved) return x_end + 2 * step.accel * step.length;
    double x = kInf;
    for (std::size_t k = 0; k < axes_.size(); ++k) {
      const Coef& q = coefs_[step.coef + k];
      const double slope = 1 - 2 * step.length * q.s_t;
      if (q.a_t < kInf && slope > 0) x = std::min(x, (x_end + 2 * step.length * q.a_t) / slope);
    }
    return x;
  }

  static double time(const Step& step, double x0, double x1) {
    const double v0 = std::sqrt(x0), v1 = std::sqrt(x1);
    if (step.curved) return 2 * step.length / (v0 + v1);
    const double a = step.accel;
    if (!(a < kInf)) return step.cap < kInf ? step.length / std::sqrt(step.cap) : 0.0;
    // Up from v0 to the peak, down to v1, cruising at the cap in between when it is reached.
    const double peak_sq =
        std::max({std::min(step.cap, 0.5 * (x0 + x1) + a * step.length), x0, x1});
    const double peak = std::sqrt(peak_sq);
    const double ramps = (2 * peak_sq - x0 - x1) / (2 * a);
    const double cruise = peak > 0 ? std::max(0.0, step.length - ramps) / peak : 0.0;
    return (2 * peak - v0 - v1) / a + cruise;
  }

  const ReferenceOptions& options_;
  double linear_v_ = 0;
  std::vector<int> axes_;
  std::array<double, kAxes> v_{}, a_{};
  std::vector<Step> steps_;
  std::vector<Coef> coefs_;
  std::vector<std::pair<std::size_t, double>> limits_;
};

}  // namespace cncd::bench::reference
