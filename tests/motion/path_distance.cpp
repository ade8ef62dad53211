#include "path_distance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cncd::test {

using motion::AxisPose;
using motion::Move;

double xyz_distance(const AxisPose& a, const AxisPose& b) {
  double sum = 0;
  for (int i = 0; i < 3; ++i)
    sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum);
}

double distance_to_move(const AxisPose& p, const AxisPose& from, const Move& move) {
  if (move.kind == Move::Kind::arc) {
    const double cx = move.center_first, cy = move.center_second;
    const double a0 = std::atan2(from[1] - cy, from[0] - cx);
    const double a1 = std::atan2(move.end[1] - cy, move.end[0] - cx);
    const double two_pi = 2 * std::numbers::pi;
    double sweep = a1 - a0;
    if (move.turns > 0 && sweep <= 0) sweep += two_pi;
    if (move.turns < 0 && sweep >= 0) sweep -= two_pi;
    double phi = std::atan2(p[1] - cy, p[0] - cx) - a0;
    while (sweep > 0 && phi < 0)
      phi += two_pi;
    while (sweep < 0 && phi > 0)
      phi -= two_pi;
    const double f = std::clamp(phi / sweep, 0.0, 1.0);
    const double r = std::hypot(from[0] - cx, from[1] - cy);
    const AxisPose on{cx + r * std::cos(a0 + f * sweep), cy + r * std::sin(a0 + f * sweep),
                      from[2] + (move.end[2] - from[2]) * f};
    return std::min({xyz_distance(p, on), xyz_distance(p, from), xyz_distance(p, move.end)});
  }
  double len_sq = 0, t = 0;
  for (int i = 0; i < 3; ++i) {
    len_sq += (move.end[i] - from[i]) * (move.end[i] - from[i]);
    t += (p[i] - from[i]) * (move.end[i] - from[i]);
  }
  t = len_sq > 0 ? std::clamp(t / len_sq, 0.0, 1.0) : 0.0;
  AxisPose on{};
  for (int i = 0; i < 3; ++i)
    on[i] = from[i] + (move.end[i] - from[i]) * t;
  return xyz_distance(p, on);
}

Move arc_to(double x, double y, double cx, double cy, int turns, double feed) {
  Move m;
  m.kind = Move::Kind::arc;
  m.end = {x, y, 0, 0, 0, 0, 0, 0, 0};
  m.center_first = cx;
  m.center_second = cy;
  m.turns = turns;
  m.feed = feed;
  return m;
}

}  // namespace cncd::test
