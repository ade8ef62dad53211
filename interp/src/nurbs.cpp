#include "cncd/interp/nurbs.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::interp {
namespace {

// Samples inside a piece against its chord: the curve is a polynomial (or rational) of degree
// below the order in each knot span, and pieces never cross more than a fraction of a span
// (see kPiecesPerSpan), so nine samples see any bulge that matters.
constexpr int kSamples = 9;
constexpr int kPiecesPerSpan = 8;
constexpr int kMaxDepth = 40;
// A piece is kept when its samples lie within this share of the tolerance: the margin covers
// the curve between the samples.
constexpr double kSampleMargin = 0.8;

}  // namespace

double xy_distance_to_segment(const Pose& p, const Pose& a, const Pose& b) {
  const double dx = b[0] - a[0];
  const double dy = b[1] - a[1];
  const double len2 = dx * dx + dy * dy;
  double t = 0;
  if (len2 > 0) t = std::clamp(((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2, 0.0, 1.0);
  return std::hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

NurbsCurve::NurbsCurve(const NurbsFeed& feed) : feed_(feed) {
  const int n = static_cast<int>(feed_.points.size());
  const int k = feed_.order;
  const double last = static_cast<double>(n - k + 1);
  knots_.reserve(static_cast<std::size_t>(n + k));
  for (int i = 0; i < n + k; ++i) {
    const int value = i < k ? 0 : i < n ? i - k + 1 : n - k + 1;
    knots_.push_back(static_cast<double>(value) / last);
  }
}

// de Boor's algorithm on the homogeneous points (w x, w y, w).
Pose NurbsCurve::at(double u) const {
  const int n = static_cast<int>(feed_.points.size());
  const int k = feed_.order;
  u = std::clamp(u, 0.0, 1.0);
  // The span: knots_[s] <= u < knots_[s + 1], the last non-empty one at u = 1.
  int s = k - 1;
  while (s < n - 1 && u >= knots_[static_cast<std::size_t>(s + 1)])
    ++s;
  double hx[32];
  double hy[32];
  double hw[32];
  double* x = hx;
  double* y = hy;
  double* w = hw;
  std::vector<double> big;
  if (k > 32) {
    big.resize(static_cast<std::size_t>(3 * k));
    x = big.data();
    y = x + k;
    w = y + k;
  }
  for (int j = 0; j < k; ++j) {
    const auto i = static_cast<std::size_t>(s - k + 1 + j);
    const double weight = feed_.weights[i];
    x[j] = weight * feed_.points[i][0];
    y[j] = weight * feed_.points[i][1];
    w[j] = weight;
  }
  for (int r = 1; r < k; ++r) {
    for (int j = k - 1; j >= r; --j) {
      const int i = s - k + 1 + j;
      const double lo = knots_[static_cast<std::size_t>(i)];
      const double hi = knots_[static_cast<std::size_t>(i + k - r)];
      const double a = hi > lo ? (u - lo) / (hi - lo) : 0.0;
      x[j] = (1 - a) * x[j - 1] + a * x[j];
      y[j] = (1 - a) * y[j - 1] + a * y[j];
      w[j] = (1 - a) * w[j - 1] + a * w[j];
    }
  }
  Pose p = feed_.points.front();
  p[0] = x[k - 1] / w[k - 1];
  p[1] = y[k - 1] / w[k - 1];
  return p;
}

void NurbsCurve::refine(double u0, const Pose& p0, double u1, const Pose& p1, double tolerance,
                        int depth, std::vector<Pose>& out) const {
  double worst = 0;
  for (int i = 1; i <= kSamples; ++i) {
    const double u = u0 + (u1 - u0) * i / (kSamples + 1);
    worst = std::max(worst, xy_distance_to_segment(at(u), p0, p1));
  }
  if (worst > kSampleMargin * tolerance && depth < kMaxDepth) {
    const double um = 0.5 * (u0 + u1);
    const Pose pm = at(um);
    refine(u0, p0, um, pm, tolerance, depth + 1, out);
    refine(um, pm, u1, p1, tolerance, depth + 1, out);
    return;
  }
  const Pose& from = out.empty() ? feed_.points.front() : out.back();
  if (std::hypot(p1[0] - from[0], p1[1] - from[1]) > 0) out.push_back(p1);
}

std::vector<Pose> NurbsCurve::polyline(double tolerance) const {
  std::vector<Pose> out;
  const int n = static_cast<int>(feed_.points.size());
  const int spans = n - feed_.order + 1;
  const int pieces = spans * kPiecesPerSpan;
  double u0 = 0;
  Pose p0 = start();
  for (int i = 1; i <= pieces; ++i) {
    const double u1 = static_cast<double>(i) / pieces;
    const Pose p1 = i == pieces ? end() : at(u1);
    refine(u0, p0, u1, p1, tolerance, 0, out);
    u0 = u1;
    p0 = p1;
  }
  // The curve ends exactly on its last point, however the pieces before it fell.
  if (out.empty() || out.back() != end()) {
    if (!out.empty() && std::hypot(out.back()[0] - end()[0], out.back()[1] - end()[1]) == 0) {
      out.back() = end();
    } else {
      out.push_back(end());
    }
  }
  return out;
}

double NurbsCurve::length() const {
  double scale = 0;
  for (const Pose& p : feed_.points)
    scale = std::max({scale, std::fabs(p[0]), std::fabs(p[1])});
  const std::vector<Pose> points = polyline(std::max(1e-9, scale * 1e-7));
  double total = 0;
  Pose from = start();
  for (const Pose& p : points) {
    total += std::hypot(p[0] - from[0], p[1] - from[1]);
    from = p;
  }
  return total;
}

}  // namespace cncd::interp
