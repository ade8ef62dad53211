// trivkins: each joint drives one axis, as JointConfig::axis says (coordinates=, or [TRAJ]
// COORDINATES in joint order). A letter driven by several joints is a gantry: its first joint
// leads the axis, and the others follow it wherever the path or a jog moves it, while homing
// moves each on its own (docs/kinematics.md).
#include <vector>

#include "kins_modules.hpp"

namespace cncd::motion {
namespace {

class TrivialKinematics final : public Kinematics {
 public:
  explicit TrivialKinematics(const config::MachineConfig& config)
      : limits_(axis_rate_limits(config)) {
    joint_axis_.fill(-1);
    lead_joint_.fill(-1);
    const int joints = static_cast<int>(std::min<std::size_t>(config.joints.size(), kJoints));
    for (int j = 0; j < joints; ++j) {
      const int axis = config::axis_index(config.joints[static_cast<std::size_t>(j)].axis);
      joint_axis_[static_cast<std::size_t>(j)] = axis;
      if (axis < 0) continue;
      axis_joints_[static_cast<std::size_t>(axis)] |= 1u << j;
      if (lead_joint_[static_cast<std::size_t>(axis)] < 0)
        lead_joint_[static_cast<std::size_t>(axis)] = j;
    }
  }

  void forward(const JointArray& joints, AxisPose& axes) const noexcept override {
    for (int axis = 0; axis < kAxes; ++axis) {
      const int j = lead_joint_[static_cast<std::size_t>(axis)];
      if (j >= 0) axes[static_cast<std::size_t>(axis)] = joints[static_cast<std::size_t>(j)];
    }
  }

  void inverse(const AxisPose& axes, std::uint32_t axis_mask,
               JointArray& joints) const noexcept override {
    for (int j = 0; j < kJoints; ++j) {
      const int axis = joint_axis_[static_cast<std::size_t>(j)];
      if (axis >= 0 && (axis_mask & (1u << axis)) != 0)
        joints[static_cast<std::size_t>(j)] = axes[static_cast<std::size_t>(axis)];
    }
  }

  std::uint32_t joints_of_axis(int axis) const noexcept override {
    return axis >= 0 && axis < kAxes ? axis_joints_[static_cast<std::size_t>(axis)] : 0;
  }

  int axis_of_joint(int joint) const noexcept override {
    return joint >= 0 && joint < kJoints ? joint_axis_[static_cast<std::size_t>(joint)] : -1;
  }

  std::span<const RateLimit> rate_limits() const noexcept override { return limits_; }
  std::uint32_t coupled_axes() const noexcept override { return 0; }

 private:
  std::array<int, kJoints> joint_axis_{};  // the axis a joint drives, -1 = none
  std::array<int, kAxes> lead_joint_{};    // the first joint of an axis, -1 = none
  std::array<std::uint32_t, kAxes> axis_joints_{};
  std::vector<RateLimit> limits_;
};

}  // namespace

std::unique_ptr<const Kinematics> make_trivkins(const config::MachineConfig& config) {
  return std::make_unique<TrivialKinematics>(config);
}

}  // namespace cncd::motion
