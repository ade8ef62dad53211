#include "cncd/interp/to_machine.hpp"

#include <cmath>
#include <numbers>

namespace cncd::interp {
namespace {

double millimetres(Units units) {
  return units == Units::inches ? 25.4 : units == Units::cm ? 10.0 : 1.0;
}

bool is_linear(std::size_t axis) {
  return axis <= 2 || axis >= 6;
}

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
    case Plane::xy:
    default:
      return {0, 1, 2};
  }
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
  switch (command.kind) {
    case CanonKind::use_length_units:
      program_units_ = static_cast<Units>(command.ivalue);
      break;
    case CanonKind::set_g5x_offset:
      g5x_ = to_machine_units(command.pos);
      break;
    case CanonKind::set_g92_offset:
      g92_ = to_machine_units(command.pos);
      break;
    case CanonKind::set_xy_rotation:
      rotation_deg_ = command.value;
      break;
    case CanonKind::use_tool_length_offset:
      tool_ = to_machine_units(command.pos);
      break;
    case CanonKind::set_feed_rate:
      feed_ = command.value * length_factor();
      out.value = feed_;
      break;
    case CanonKind::straight_traverse:
    case CanonKind::straight_feed:
      out.pos = machine_pose(command.pos);
      break;
    case CanonKind::arc_feed: {
      const ArcAxes axes = arc_axes(command.plane);
      Pose end = command.pos;
      end[axes.first] = command.first_end;
      end[axes.second] = command.second_end;
      end[axes.normal] = command.axis_end_point;
      Pose center = end;
      center[axes.first] = command.first_axis;
      center[axes.second] = command.second_axis;
      const Pose machine_end = machine_pose(end);
      const Pose machine_center = machine_pose(center);
      out.pos = machine_end;
      out.first_end = machine_end[axes.first];
      out.second_end = machine_end[axes.second];
      out.axis_end_point = machine_end[axes.normal];
      out.first_axis = machine_center[axes.first];
      out.second_axis = machine_center[axes.second];
      break;
    }
    default:
      break;
  }
  return out;
}

}  // namespace cncd::interp
