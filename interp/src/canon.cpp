#include "cncd/interp/canon.hpp"

#include <cmath>

namespace cncd::interp {

PlaneAxes plane_axes(Plane plane) {
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

Pose ArcFeed::end() const {
  const PlaneAxes axes = plane_axes(plane);
  Pose pose{};
  pose[axes.first] = first_end;
  pose[axes.second] = second_end;
  pose[axes.normal] = axis_end_point;
  for (std::size_t axis = 3; axis < kAxes; ++axis)
    pose[axis] = abc_uvw[axis - 3];
  return pose;
}

Pose ArcFeed::center() const {
  const PlaneAxes axes = plane_axes(plane);
  Pose pose = end();
  pose[axes.first] = first_axis;
  pose[axes.second] = second_axis;
  return pose;
}

void ArcFeed::set_end(const Pose& end) {
  const PlaneAxes axes = plane_axes(plane);
  first_end = end[axes.first];
  second_end = end[axes.second];
  axis_end_point = end[axes.normal];
  for (std::size_t axis = 3; axis < kAxes; ++axis)
    abc_uvw[axis - 3] = end[axis];
}

void ArcFeed::set_center(const Pose& center) {
  const PlaneAxes axes = plane_axes(plane);
  first_axis = center[axes.first];
  second_axis = center[axes.second];
}

namespace {

bool finite(const Pose& pose) {
  bool all = true;
  for (const double v : pose)
    all = all && std::isfinite(v);
  return all;
}

}  // namespace

bool all_finite(const CanonOp& op) {
  return std::visit(Overloaded{
                        [](const StraightTraverse& c) { return finite(c.end); },
                        [](const StraightFeed& c) { return finite(c.end); },
                        [](const ArcFeed& c) { return finite(c.end()) && finite(c.center()); },
                        [](const NurbsFeed& c) {
                          bool all = std::isfinite(c.inverse_time_feed);
                          for (const Pose& point : c.points)
                            all = all && finite(point);
                          for (const double w : c.weights)
                            all = all && std::isfinite(w);
                          return all;
                        },
                        [](const Dwell& c) { return std::isfinite(c.seconds); },
                        [](const SetFeedRate& c) { return std::isfinite(c.rate); },
                        [](const SetG5xOffset& c) { return finite(c.offset); },
                        [](const SetG92Offset& c) { return finite(c.offset); },
                        [](const SetXyRotation& c) { return std::isfinite(c.degrees); },
                        [](const UseToolLengthOffset& c) { return finite(c.offset); },
                        [](const SetMotionControlMode& c) { return std::isfinite(c.tolerance); },
                        [](const SetNaivecamTolerance& c) { return std::isfinite(c.tolerance); },
                        [](const SetSpindleSpeed& c) { return std::isfinite(c.rpm); },
                        [](const SetSpindleMode& c) { return std::isfinite(c.css_max_rpm); },
                        [](const OrientSpindle& c) { return std::isfinite(c.angle_deg); },
                        [](const WaitOrientSpindle& c) { return std::isfinite(c.timeout_s); },
                        [](const SetOutputValue& c) { return std::isfinite(c.value); },
                        [](const WaitInput& c) { return std::isfinite(c.timeout_s); },
                        [](const UserMCode& c) { return std::isfinite(c.p) && std::isfinite(c.q); },
                        [](const StraightProbe& c) { return finite(c.end); },
                        [](const RigidTap& c) { return finite(c.end) && std::isfinite(c.scale); },
                        [](const StartSpeedFeedSynch& c) { return std::isfinite(c.feed_per_rev); },
                        [](const SetToolTableEntry& c) {
                          return finite(c.offset) && std::isfinite(c.front_angle) &&
                                 std::isfinite(c.back_angle);
                        },
                        [](const auto&) { return true; },  // no number in it
                    },
                    op);
}

}  // namespace cncd::interp
