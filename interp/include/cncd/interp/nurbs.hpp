// The exact curve of a NurbsFeed and its cut into straight pieces that stay within a given
// distance of it. The knot vector is the clamped uniform one of the curve's order (LinuxCNC's
// G5.2): `order` zeros, the interior knots evenly spaced, `order` ones; with as many points as
// its order that is the Bezier curve of G5 and G5.1.
#pragma once

#include <vector>

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

class NurbsCurve {
 public:
  // The feed must have at least `order` points and as many positive weights; order >= 2.
  explicit NurbsCurve(const NurbsFeed& feed);

  // The point at parameter u in [0, 1]: X and Y on the curve, the other axes those of the
  // first point (the curve lies in the XY plane).
  Pose at(double u) const;
  const Pose& start() const { return feed_.points.front(); }
  const Pose& end() const { return feed_.points.back(); }

  // Points after the start along the curve, the last exactly end(), such that each straight
  // piece between consecutive points (the first from start()) stays within `tolerance` of the
  // curve over its parameter interval. Pieces of zero length are left out.
  std::vector<Pose> polyline(double tolerance) const;

  // The length of the curve (of a polyline within a micrometre-scale tolerance of it).
  double length() const;

 private:
  void refine(double u0, const Pose& p0, double u1, const Pose& p1, double tolerance, int depth,
              std::vector<Pose>& out) const;

  NurbsFeed feed_;
  std::vector<double> knots_;  // normalised to [0, 1]
};

// The distance from `p` to the segment a-b in the XY plane.
double xy_distance_to_segment(const Pose& p, const Pose& a, const Pose& b);

}  // namespace cncd::interp
