#include "path_smooth.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <numeric>

#include "path_reference.hpp"

namespace cncd::bench {
namespace {

using motion::AxisPose;
using motion::kAxes;
using motion::Segment;

double norm(const AxisPose& a) {
  return std::sqrt(std::inner_product(a.begin(), a.end(), a.begin(), 0.0));
}

AxisPose minus(const AxisPose& a, const AxisPose& b) {
  AxisPose d{};
  for (int i = 0; i < kAxes; ++i)
    d[i] = a[i] - b[i];
  return d;
}

bool euclidean_line(const Segment& s) {
  const double n = norm(minus(s.end, s.start));
  return s.kind == Segment::Kind::line && s.feed > 0 && s.length > 0 &&
         std::abs(n - s.length) <= 1e-9 * std::max(1.0, s.length);
}

// Whether `next` continues the run that `prev` is in.
bool continues(const Segment& prev, const Segment& next) {
  return euclidean_line(next) && next.feed == prev.feed &&
         norm(minus(next.start, prev.end)) <= 1e-9;
}

// The flow on one run's vertices p (the ends stay).
void smooth_run(const std::vector<AxisPose>& p, std::vector<AxisPose>& q,
                const SmoothOptions& options) {
  const std::size_t n = p.size();
  q = p;
  if (n < 3) return;
  // A vertex's second difference against the point at its share of the chord between its
  // neighbours (zero on a straight run whatever the spacing), with the programmed spacing.
  std::vector<double> a(n, 0.0);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double l1 = norm(minus(p[i], p[i - 1])), l2 = norm(minus(p[i + 1], p[i]));
    a[i] = l2 / (l1 + l2);
  }
  // Only the axes the run moves (the others stay where they are).
  std::vector<int> axes;
  for (int k = 0; k < kAxes; ++k)
    if (std::any_of(p.begin(), p.end(), [&](const AxisPose& x) { return x[k] != p[0][k]; }))
      axes.push_back(k);
  std::vector<AxisPose> lap(n, AxisPose{});
  AxisPose step{}, t{}, moved{};
  for (int it = 0; it < options.iterations; ++it) {
    for (std::size_t i = 1; i + 1 < n; ++i)
      for (int k : axes)
        lap[i][k] = a[i] * q[i - 1][k] + (1 - a[i]) * q[i + 1][k] - q[i][k];
    for (std::size_t i = 1; i + 1 < n; ++i) {
      double tn = 0, along = 0, off = 0;
      for (int k : axes) {
        t[k] = q[i + 1][k] - q[i - 1][k];
        tn += t[k] * t[k];
      }
      tn = std::sqrt(tn);
      for (int k : axes) {
        step[k] = -options.rate * (a[i] * lap[i - 1][k] + (1 - a[i]) * lap[i + 1][k] - lap[i][k]);
        t[k] = tn > 0 ? t[k] / tn : 0.0;
        along += step[k] * t[k];
      }
      for (int k : axes) {
        moved[k] = q[i][k] + step[k] - along * t[k] - p[i][k];
        off += moved[k] * moved[k];
      }
      off = std::sqrt(off);
      const double scale = off > options.shift ? options.shift / off : 1.0;
      for (int k : axes)
        q[i][k] = p[i][k] + scale * moved[k];
    }
  }
}

double point_to_line(const AxisPose& x, const Segment& s) {
  const AxisPose d = minus(s.end, s.start);
  const double len_sq = std::inner_product(d.begin(), d.end(), d.begin(), 0.0);
  double t = 0;
  if (len_sq > 0) {
    for (int k = 0; k < kAxes; ++k)
      t += (x[k] - s.start[k]) * d[k];
    t = std::clamp(t / len_sq, 0.0, 1.0);
  }
  AxisPose off{};
  for (int k = 0; k < kAxes; ++k)
    off[k] = x[k] - s.start[k] - t * d[k];
  return norm(off);
}

}  // namespace

std::vector<Segment> smoothed_lines(const std::vector<Segment>& moves,
                                    const SmoothOptions& options) {
  std::vector<Segment> out = moves;
  std::vector<AxisPose> p, q;
  for (std::size_t i = 0; i < moves.size();) {
    if (!euclidean_line(moves[i])) {
      ++i;
      continue;
    }
    std::size_t end = i + 1;
    while (end < moves.size() && continues(moves[end - 1], moves[end]))
      ++end;
    p.clear();
    p.push_back(moves[i].start);
    for (std::size_t k = i; k < end; ++k)
      p.push_back(moves[k].end);
    smooth_run(p, q, options);
    for (std::size_t k = i; k < end; ++k) {
      Segment& s = out[k];
      s.start = q[k - i];
      s.end = q[k - i + 1];
      s.length = norm(minus(s.end, s.start));
    }
    i = end;
  }
  return out;
}

double polyline_deviation(const std::vector<Segment>& programmed, const std::vector<Segment>& path,
                          double step, int window) {
  double worst = 0;
  const auto count = static_cast<std::ptrdiff_t>(std::min(programmed.size(), path.size()));
  for (std::ptrdiff_t i = 0; i < count; ++i) {
    const Segment& s = path[static_cast<std::size_t>(i)];
    if (s.kind != Segment::Kind::line) continue;
    const auto n = static_cast<int>(std::ceil(s.length / step)) + 1;
    for (int k = 0; k <= n; ++k) {
      AxisPose x{};
      for (int a = 0; a < kAxes; ++a)
        x[a] = s.start[a] + (s.end[a] - s.start[a]) * k / n;
      double nearest = std::numeric_limits<double>::infinity();
      for (std::ptrdiff_t j = std::max<std::ptrdiff_t>(0, i - window);
           j <= std::min(count - 1, i + window); ++j) {
        const Segment& o = programmed[static_cast<std::size_t>(j)];
        if (o.kind == Segment::Kind::line) nearest = std::min(nearest, point_to_line(x, o));
      }
      if (std::isfinite(nearest)) worst = std::max(worst, nearest);
    }
  }
  return worst;
}

void print_smoothed(const config::MachineConfig& machine, const std::vector<Segment>& moves,
                    double tolerance, double merge_tolerance, double bound_s) {
  if (!(tolerance > 0)) return;
  const auto started = std::chrono::steady_clock::now();
  SmoothOptions smooth;
  smooth.shift = 0.5 * tolerance;
  const std::vector<Segment> smoothed = smoothed_lines(moves, smooth);
  ReferenceOptions half;
  half.blend_corners = true;
  half.tolerance = 0.5 * tolerance;
  const PathReference ref_smoothed = time_optimal(machine, smoothed, half);
  ReferenceOptions half_merged = half;
  half_merged.merge_tolerance = 0.5 * tolerance;
  const PathReference ref_half = time_optimal(machine, moves, half_merged);
  const double moved = polyline_deviation(moves, smoothed, 0.05 * tolerance);
  std::printf(
      "    within P%g: smoothed (vertices moved up to %g, measured %.4f; blends within %g) %.3f s "
      "(%.4f x bound)   merged within %g, blended within %g %.3f s (%.4f x bound)\n"
      "    within P, Q with P and Q",
      tolerance, smooth.shift, moved, half.tolerance, ref_smoothed.time_s,
      ref_smoothed.time_s / bound_s, half.tolerance, half.tolerance, ref_half.time_s,
      ref_half.time_s / bound_s);
  for (double scale : {2.0, 4.0, 10.0}) {
    ReferenceOptions wider;
    wider.blend_corners = true;
    wider.tolerance = scale * tolerance;
    wider.merge_tolerance = scale * merge_tolerance;
    const double s = time_optimal(machine, moves, wider).time_s;
    std::printf("  x%g: %.3f s (%.4f x bound)", scale, s, s / bound_s);
  }
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started;
  std::printf(" (%.2f s)\n", took.count());
}

}  // namespace cncd::bench
