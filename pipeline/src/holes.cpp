#include "cncd/pipeline/holes.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace cncd::pipeline {
namespace {

constexpr std::size_t kZ = 2;

// The same coordinate, give or take the rounding of an offset or a unit conversion.
bool same(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a));
}

// Only Z changes (or nothing): the tool stays over the same point of the part.
bool along_z(const interp::Pose& from, const interp::Pose& to) {
  for (std::size_t axis = 0; axis < from.size(); ++axis) {
    if (axis != kZ && !same(from[axis], to[axis])) return false;
  }
  return true;
}

}  // namespace

void HoleFinder::straight(const interp::Pose& from, const interp::Pose& to, bool feed, int line) {
  if (!along_z(from, to)) {
    open_ = false;
    return;
  }
  if (open_) {
    holes_.back().bottom = std::min(holes_.back().bottom, to[kZ]);
    return;
  }
  if (feed && to[kZ] < from[kZ] && !same(to[kZ], from[kZ])) {
    holes_.push_back(Hole{line, from[0], from[1], from[kZ], to[kZ]});
    open_ = true;
  }
}

}  // namespace cncd::pipeline
