// Offsets and pass-line intersections of the G7x profile.
#include "g7x_profile.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace cncd::interp::g7x {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double radius(const Seg& s) {
  return std::hypot(s.a.u - s.c.u, s.a.v - s.c.v);
}

double angle_of(const Seg& s, Pt p) {
  return std::atan2(p.v - s.c.v, p.u - s.c.u);
}

// How far the arc turns from its start to `p`, in [0, 2pi).
double sweep_to(const Seg& s, Pt p) {
  double sweep = angle_of(s, p) - angle_of(s, s.a);
  if (!s.ccw) sweep = -sweep;
  while (sweep < 0)
    sweep += kTwoPi;
  while (sweep >= kTwoPi)
    sweep -= kTwoPi;
  return sweep;
}

double full_sweep(const Seg& s) {
  const double sweep = sweep_to(s, s.b);
  return sweep < kEps ? kTwoPi : sweep;
}

bool on_arc(const Seg& s, Pt p) {
  return sweep_to(s, p) <= full_sweep(s) + 1e-12;
}

// The direction of travel at the start (at_end false) or the end of `s`, of unit length.
Pt tangent(const Seg& s, bool at_end) {
  if (!s.arc) {
    const double len = std::hypot(s.b.u - s.a.u, s.b.v - s.a.v);
    return {(s.b.u - s.a.u) / len, (s.b.v - s.a.v) / len};
  }
  const Pt p = at_end ? s.b : s.a;
  const double r = radius(s);
  const double ru = (p.u - s.c.u) / r;
  const double rv = (p.v - s.c.v) / r;
  return s.ccw ? Pt{-rv, ru} : Pt{rv, -ru};
}

Seg offset_one(const Seg& s, double d) {
  Seg out = s;
  if (!s.arc) {
    const Pt t = tangent(s, false);
    out.a = {s.a.u - t.v * d, s.a.v + t.u * d};
    out.b = {s.b.u - t.v * d, s.b.v + t.u * d};
    return out;
  }
  // Left of a counter-clockwise arc is toward its center.
  const double r = radius(s);
  const double scale = (s.ccw ? r - d : r + d) / r;
  out.a = {s.c.u + (s.a.u - s.c.u) * scale, s.c.v + (s.a.v - s.c.v) * scale};
  const double rb = std::hypot(s.b.u - s.c.u, s.b.v - s.c.v);
  const double scale_b = (s.ccw ? rb - d : rb + d) / rb;
  out.b = {s.c.u + (s.b.u - s.c.u) * scale_b, s.c.v + (s.b.v - s.c.v) * scale_b};
  return out;
}

// Where the circle or line carrying `x` meets the one carrying `y`, nearest to `near`.
std::optional<Pt> meet(const Seg& x, const Seg& y, Pt near) {
  std::vector<Pt> points;
  if (!x.arc && !y.arc) {
    const double d1u = x.b.u - x.a.u, d1v = x.b.v - x.a.v;
    const double d2u = y.b.u - y.a.u, d2v = y.b.v - y.a.v;
    const double den = d1u * d2v - d1v * d2u;
    if (std::fabs(den) < 1e-15) return std::nullopt;
    const double t = ((y.a.u - x.a.u) * d2v - (y.a.v - x.a.v) * d2u) / den;
    return Pt{x.a.u + t * d1u, x.a.v + t * d1v};
  }
  if (x.arc && y.arc) {
    const double ra = radius(x), rb = radius(y);
    const double du = y.c.u - x.c.u, dv = y.c.v - x.c.v;
    const double dist = std::hypot(du, dv);
    if (dist < kEps) return std::nullopt;
    const double along = (ra * ra - rb * rb + dist * dist) / (2 * dist);
    const double h2 = ra * ra - along * along;
    if (h2 < 0) return std::nullopt;
    const double h = std::sqrt(h2);
    const Pt m{x.c.u + along * du / dist, x.c.v + along * dv / dist};
    points.push_back({m.u - h * dv / dist, m.v + h * du / dist});
    points.push_back({m.u + h * dv / dist, m.v - h * du / dist});
  } else {
    const Seg& line = x.arc ? y : x;
    const Seg& circle = x.arc ? x : y;
    const double r = radius(circle);
    const double du = line.b.u - line.a.u, dv = line.b.v - line.a.v;
    const double fu = line.a.u - circle.c.u, fv = line.a.v - circle.c.v;
    const double qa = du * du + dv * dv;
    const double qb = 2 * (fu * du + fv * dv);
    const double qc = fu * fu + fv * fv - r * r;
    double disc = qb * qb - 4 * qa * qc;
    // A line that misses the circle by a hair (a corner meant to be smooth, written with
    // rounded numbers) meets it where it comes closest.
    if (disc < 0 && -disc < 8e-3 * qa * r) disc = 0;  // missing by less than 0.001
    if (disc < 0) return std::nullopt;
    for (const double sign : {-1.0, 1.0}) {
      const double t = (-qb + sign * std::sqrt(disc)) / (2 * qa);
      points.push_back({line.a.u + t * du, line.a.v + t * dv});
    }
  }
  auto distance = [&](Pt p) { return std::hypot(p.u - near.u, p.v - near.v); };
  return *std::min_element(points.begin(), points.end(),
                           [&](Pt p, Pt q) { return distance(p) < distance(q); });
}

// Whether `p`, a point on the line or circle carrying `s`, lies within `s` or less than 0.001
// beyond one of its ends.
bool contains(const Seg& s, Pt p) {
  constexpr double kSlack = 1e-3;
  if (s.arc) {
    const double slack = kSlack / radius(s);
    const double sweep = sweep_to(s, p);
    return sweep <= full_sweep(s) + slack || sweep >= kTwoPi - slack;
  }
  const double du = s.b.u - s.a.u, dv = s.b.v - s.a.v;
  const double len = std::hypot(du, dv);
  const double along = ((p.u - s.a.u) * du + (p.v - s.a.v) * dv) / len;
  return along >= -kSlack && along <= len + kSlack;
}

bool same(Pt p, Pt q) {
  return std::fabs(p.u - q.u) < 1e-7 && std::fabs(p.v - q.v) < 1e-7;
}

}  // namespace

Path round_corners(const Path& path) {
  Path out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    Seg next = path[i];
    if (!out.empty() && out.back().round > 0 && !out.back().arc && !next.arc) {
      Seg& prev = out.back();
      const Pt t1 = tangent(prev, true);
      const Pt t2 = tangent(next, false);
      const double turn = t1.u * t2.v - t1.v * t2.u;
      const double cosine = t1.u * t2.u + t1.v * t2.v;
      const double angle = std::atan2(std::fabs(turn), cosine);
      const double r = prev.round;
      const double cut = r * std::tan(angle / 2);
      const Pt corner = next.a;
      const Pt from{corner.u - t1.u * cut, corner.v - t1.v * cut};
      const Pt to{corner.u + t2.u * cut, corner.v + t2.v * cut};
      // The center lies on the side the path turns to.
      const double side = turn > 0 ? 1.0 : -1.0;
      const Pt center{from.u - t1.v * r * side, from.v + t1.u * r * side};
      prev.b = from;
      next.a = to;
      if (std::fabs(turn) > kEps) out.push_back(Seg{from, to, true, center, turn > 0, 0});
    }
    out.push_back(next);
  }
  return out;
}

Path offset_path(const Path& path, double d) {
  if (d == 0.0) return path;
  Path out;
  std::size_t prev_index = 0;  // the piece of `path` that out.back() is the offset of
  for (std::size_t i = 0; i < path.size(); ++i) {
    // An arc around the inside of a corner no larger than the offset vanishes from it.
    if (path[i].arc && (path[i].ccw ? radius(path[i]) - d : radius(path[i]) + d) <= kEps) continue;
    Seg next = offset_one(path[i], d);
    if (!out.empty()) {
      Seg& prev = out.back();
      const Pt corner = path[i].a;
      if (!same(prev.b, next.a)) {
        const Pt t1 = tangent(path[prev_index], true);
        const Pt t2 = tangent(path[i], false);
        const double turn = t1.u * t2.v - t1.v * t2.u;
        // Pieces that still cross (an inside corner, or one so nearly straight that the
        // offsets overlap) are cut where they do; an outside corner gets its arc.
        const auto p = meet(prev, next, corner);
        if (p && (turn >= 0 || (contains(prev, *p) && contains(next, *p)))) {
          prev.b = *p;
          next.a = *p;
        } else if (turn < 0) {
          out.push_back(Seg{prev.b, next.a, true, corner, false, 0});
        }
      }
    }
    out.push_back(next);
    prev_index = i;
  }
  return out;
}

void level_hits(const Seg& seg, double level, std::vector<double>& out) {
  if (!seg.arc) {
    const double lo = std::min(seg.a.u, seg.b.u), hi = std::max(seg.a.u, seg.b.u);
    if (level < lo - kEps || level > hi + kEps) return;
    if (std::fabs(seg.b.u - seg.a.u) < kEps) {
      out.push_back(seg.a.v);
      out.push_back(seg.b.v);
      return;
    }
    const double t = (level - seg.a.u) / (seg.b.u - seg.a.u);
    out.push_back(seg.a.v + t * (seg.b.v - seg.a.v));
    return;
  }
  const double r = radius(seg);
  const double du = level - seg.c.u;
  if (std::fabs(du) > r + kEps) return;
  const double h = std::sqrt(std::max(0.0, r * r - du * du));
  for (const double v : {seg.c.v + h, seg.c.v - h}) {
    if (on_arc(seg, {level, v})) out.push_back(v);
  }
}

double next_hit(const Path& path, double level, double below, double fallback) {
  std::vector<double> hits;
  for (const Seg& seg : path)
    level_hits(seg, level, hits);
  double best = fallback;
  bool found = false;
  for (const double v : hits) {
    if (v < below - 1e-7 && (!found || v > best)) {
      best = v;
      found = true;
    }
  }
  return best;
}

Pt point_at(const Seg& seg, double level, bool last) {
  if (!seg.arc) {
    if (std::fabs(seg.b.u - seg.a.u) < kEps) return seg.a;
    const double t = (level - seg.a.u) / (seg.b.u - seg.a.u);
    return {level, seg.a.v + t * (seg.b.v - seg.a.v)};
  }
  std::vector<double> hits;
  level_hits(seg, level, hits);
  Pt best = seg.b;
  double best_sweep = kTwoPi * 2;
  for (const double v : hits) {
    const double sweep = sweep_to(seg, {level, v}) * (last ? -1.0 : 1.0);
    if (sweep < best_sweep) {
      best_sweep = sweep;
      best = {level, v};
    }
  }
  return best;
}

Seg head(const Seg& seg, Pt p) {
  Seg out = seg;
  out.b = p;
  return out;
}

Seg tail(const Seg& seg, Pt p) {
  Seg out = seg;
  out.a = p;
  return out;
}

bool v_never_rises(const Seg& seg) {
  if (seg.b.v > seg.a.v + kEps) return false;
  if (!seg.arc) return true;
  // An arc turns back in v where it passes the top or the bottom of its circle between its ends.
  const double r = radius(seg);
  for (const Pt turn : {Pt{seg.c.u, seg.c.v + r}, Pt{seg.c.u, seg.c.v - r}}) {
    const double sweep = sweep_to(seg, turn);
    if (sweep > 1e-9 && sweep < full_sweep(seg) - 1e-9) return false;
  }
  return true;
}

bool descends(const Seg& seg) {
  return seg.b.u < seg.a.u - kEps;
}

std::optional<Pt> arc_peak(const Seg& seg) {
  const Pt top{seg.c.u + radius(seg), seg.c.v};
  if (on_arc(seg, top)) return top;
  return std::nullopt;
}

std::optional<Pt> arc_valley(const Seg& seg) {
  const Pt bottom{seg.c.u - radius(seg), seg.c.v};
  if (on_arc(seg, bottom)) return bottom;
  return std::nullopt;
}

double lowest_u(const Path& path) {
  double low = path.empty() ? 0.0 : path.front().a.u;
  for (const Seg& seg : path) {
    low = std::min({low, seg.a.u, seg.b.u});
    if (const std::optional<Pt> bottom = seg.arc ? arc_valley(seg) : std::nullopt)
      low = std::min(low, bottom->u);
  }
  return low;
}

}  // namespace cncd::interp::g7x
