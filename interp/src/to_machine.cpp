#include "cncd/interp/to_machine.hpp"

#include <cmath>
#include <numbers>
#include <variant>

namespace cncd::interp {
namespace {

double millimetres(Units units) {
  return units == Units::inches ? 25.4 : units == Units::cm ? 10.0 : 1.0;
}

bool is_linear(std::size_t axis) {
  return axis <= 2 || axis >= 6;
}

}  // namespace

double MachineTracker::length_factor() const {
  return millimetres(program_units_) / millimetres(machine_units_);
}

// Offsets are kept in machine units, converted with the program units in force when they
// were set (as LinuxCNC's canon does), so a later G20/G21 does not change them.
Pose MachineTracker::machine_pose(const Pose& program) const {
  const double factor = length_factor();
  Pose p = program;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (is_linear(axis)) p[axis] *= factor;
    p[axis] += g92_[axis];
  }
  if (rotation_deg_ != 0.0) {
    const double angle = rotation_deg_ * std::numbers::pi / 180.0;
    const double x = p[0] * std::cos(angle) - p[1] * std::sin(angle);
    const double y = p[0] * std::sin(angle) + p[1] * std::cos(angle);
    p[0] = x;
    p[1] = y;
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    p[axis] += g5x_[axis] + tool_[axis];
  return p;
}

Pose MachineTracker::to_machine_units(const Pose& program) const {
  Pose p = program;
  const double factor = length_factor();
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (is_linear(axis)) p[axis] *= factor;
  }
  return p;
}

CanonCommand MachineTracker::to_machine(const CanonCommand& command) {
  CanonCommand out = command;
  std::visit(Overloaded{
                 [&](const UseLengthUnits& c) { program_units_ = c.units; },
                 [&](const SetG5xOffset& c) { g5x_ = to_machine_units(c.offset); },
                 [&](const SetG92Offset& c) { g92_ = to_machine_units(c.offset); },
                 [&](const SetXyRotation& c) { rotation_deg_ = c.degrees; },
                 [&](const UseToolLengthOffset& c) { tool_ = to_machine_units(c.offset); },
                 [&](SetFeedRate& c) {
                   feed_ = c.rate * length_factor();
                   c.rate = feed_;
                 },
                 [&](StraightTraverse& c) { c.end = machine_pose(c.end); },
                 [&](StraightFeed& c) { c.end = machine_pose(c.end); },
                 [&](StraightProbe& c) { c.end = machine_pose(c.end); },
                 [&](RigidTap& c) { c.end = machine_pose(c.end); },
                 [&](StartSpeedFeedSynch& c) { c.feed_per_rev *= length_factor(); },
                 [&](NurbsFeed& c) {
                   // An affine map of the control points maps the curve: offsets, rotation
                   // and units apply point by point.
                   for (Pose& point : c.points)
                     point = machine_pose(point);
                   c.inverse_time_feed *= length_factor();
                 },
                 [&](ArcFeed& c) {
                   const Pose machine_center = machine_pose(c.center());
                   c.set_end(machine_pose(c.end()));
                   c.set_center(machine_center);
                 },
                 [](const auto&) {},
             },
             out.op);
  return out;
}

}  // namespace cncd::interp
