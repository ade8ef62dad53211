// The machine's geometry: how the joints (what the drives move) and the axes (what programs
// name) relate, chosen by [KINS] KINEMATICS (docs/kinematics.md). Everything that turns one
// into the other (the servo loop, homing, jogs, probing, status, the plan simulation) and the
// planner's joint limits go through this interface, and the joint-to-axis map is written
// nowhere else.
//
// trivkins: each joint drives one axis (coordinates= or [TRAJ] COORDINATES; a letter repeated
// is a gantry, its first joint leads the axis). corexykins: joint 0 = X + Y and joint 1 =
// X - Y (the two belt motors), joint n = the n-th of XYZABCUVW from joint 2 on.
// xyzac-trt-kins, xyzbc-trt-kins: joints 0-4 drive X Y Z A C (X Y Z B C) one to one, as
// LinuxCNC's identity mode; under TCP (M428) the planner turns the programmed tool tip into
// those joints with tcp_inverse() (docs/kinematics.md).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

// A bound the planner keeps along every path: the rate sum_k coefficient_k x (axis_k's speed)
// stays within max_velocity, and the same sum of the axes' accelerations within
// max_acceleration. A joint of a kinematics whose Jacobian is constant gives one (its row); an
// axis gives its own (one term, coefficient 1).
struct RateLimit {
  struct Term {
    int axis = 0;
    double coefficient = 0;
  };
  std::array<Term, kAxes> terms{};
  int count = 0;
  double max_velocity = 0;      // units/s
  double max_acceleration = 0;  // units/s^2

  // RT. sum coefficient_k x v[axis_k].
  CNCD_RT double dot(const AxisPose& v) const noexcept {
    double sum = 0;
    for (int k = 0; k < count; ++k) {
      const Term& t = terms[static_cast<std::size_t>(k)];
      sum += t.coefficient * v[static_cast<std::size_t>(t.axis)];
    }
    return sum;
  }
  // RT. The coefficient on `axis` (0 when the row has none).
  CNCD_RT double coefficient(int axis) const noexcept {
    for (int k = 0; k < count; ++k) {
      if (terms[static_cast<std::size_t>(k)].axis == axis)
        return terms[static_cast<std::size_t>(k)].coefficient;
    }
    return 0;
  }
};

inline constexpr std::uint32_t kAllAxes = (1u << kAxes) - 1;

// The most bounds any kinematics gives: one an axis and one a joint.
inline constexpr int kMaxRateLimits = kAxes + kJoints;

class Kinematics {
 public:
  virtual ~Kinematics() = default;

  // RT. The axes the joints drive, from `joints`; the other entries of `axes` are kept.
  CNCD_RT virtual void forward(const JointArray& joints, AxisPose& axes) const noexcept = 0;
  // RT. The joints that move with an axis of `axis_mask` (bit i: axis i) set for `axes`; the
  // other joints are kept (extra joints, the gantry joints of an axis that is not in the mask).
  CNCD_RT virtual void inverse(const AxisPose& axes, std::uint32_t axis_mask,
                               JointArray& joints) const noexcept = 0;
  // RT. Bit j set: joint j moves when axis `axis` does.
  CNCD_RT virtual std::uint32_t joints_of_axis(int axis) const noexcept = 0;
  // RT. The axis joint `joint` drives alone, or -1 (a corexy motor, an extra joint).
  CNCD_RT virtual int axis_of_joint(int joint) const noexcept = 0;
  // Any thread. What the planner keeps every move within: each axis's limits, and each
  // joint's where a joint is no axis of its own. trivkins gives the axes' alone, as LinuxCNC
  // plans in world coordinates.
  virtual std::span<const RateLimit> rate_limits() const noexcept = 0;
  // Bit i set: axis i shares a joint with another axis (corexy's X and Y).
  virtual std::uint32_t coupled_axes() const noexcept = 0;

  // Tool centre point control (the table-rotary modules). `machine`: the pose the joints
  // give (forward()'s axes: where the tool's controlled point stands and the rotaries'
  // angles); `part`: the same point in the part's frame, the coordinates it would have with
  // every rotary at 0, the rotaries' angles the same. The tool tip, `tool_length` below the
  // controlled point along Z, is the point the table's turns carry: `tool_length` is the Z of
  // the tool length offset in force (G43, machine units), as LinuxCNC nets motion.tooloffset.z
  // to the module's tool-offset pin; 0 (G49) stands for [KINS] TOOL_OFFSET. Without TCP both
  // are the identity.
  virtual bool has_tcp() const noexcept { return false; }
  // RT. The part pose of a machine pose.
  CNCD_RT virtual void tcp_forward(const AxisPose& machine, double tool_length,
                                   AxisPose& part) const noexcept {
    (void)tool_length;
    part = machine;
  }
  // RT. The machine pose that puts the tool at a part pose.
  CNCD_RT virtual void tcp_inverse(const AxisPose& part, double tool_length,
                                   AxisPose& machine) const noexcept {
    (void)tool_length;
    machine = part;
  }
};

// Non-RT. The kinematics [KINS] KINEMATICS names (config::MachineConfig::kinematics, which the
// config loader has checked): trivkins with its joint map (JointConfig::axis), corexykins,
// xyzac-trt-kins or xyzbc-trt-kins (MachineConfig::table_rotary).
std::unique_ptr<const Kinematics> make_kinematics(const config::MachineConfig& config);

}  // namespace cncd::motion
