#include "cncd/interp/canon.hpp"

namespace cncd::interp {
namespace {

struct ArcAxes {
  std::size_t first;
  std::size_t second;
  std::size_t normal;
};

ArcAxes arc_axes(Plane plane) {
  switch (plane) {
    case Plane::xz:
      return {2, 0, 1};
    case Plane::yz:
      return {1, 2, 0};
    case Plane::uv:
      return {6, 7, 8};
    case Plane::vw:
      return {7, 8, 6};
    case Plane::uw:
      return {8, 6, 7};
    case Plane::xy:
    default:
      return {0, 1, 2};
  }
}

}  // namespace

Pose ArcFeed::end() const {
  const ArcAxes axes = arc_axes(plane);
  Pose pose{};
  pose[axes.first] = first_end;
  pose[axes.second] = second_end;
  pose[axes.normal] = axis_end_point;
  for (std::size_t axis = 3; axis < kAxes; ++axis)
    pose[axis] = abc_uvw[axis - 3];
  return pose;
}

Pose ArcFeed::center() const {
  const ArcAxes axes = arc_axes(plane);
  Pose pose = end();
  pose[axes.first] = first_axis;
  pose[axes.second] = second_axis;
  return pose;
}

void ArcFeed::set_end(const Pose& end) {
  const ArcAxes axes = arc_axes(plane);
  first_end = end[axes.first];
  second_end = end[axes.second];
  axis_end_point = end[axes.normal];
  for (std::size_t axis = 3; axis < kAxes; ++axis)
    abc_uvw[axis - 3] = end[axis];
}

void ArcFeed::set_center(const Pose& center) {
  const ArcAxes axes = arc_axes(plane);
  first_axis = center[axes.first];
  second_axis = center[axes.second];
}

}  // namespace cncd::interp
