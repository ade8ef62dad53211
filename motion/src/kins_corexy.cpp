// corexykins, as LinuxCNC defines it: the two belt motors are joints 0 and 1, joint 0 = X + Y
// and joint 1 = X - Y, so X = (j0 + j1) / 2 and Y = (j0 - j1) / 2; joint n (n >= 2) drives
// the n-th axis of XYZABCUVW. A move along a diagonal turns one motor alone at sqrt(2) times
// the path speed: the planner keeps both motors within their own MAX_VELOCITY and
// MAX_ACCELERATION as well as the axes within theirs (docs/kinematics.md).
#include <vector>

#include "kins_modules.hpp"

namespace cncd::motion {
namespace {

constexpr std::uint32_t kXY = 0b11;

class CoreXyKinematics final : public Kinematics {
 public:
  explicit CoreXyKinematics(const config::MachineConfig& config)
      : joints_(std::min(kAxes, static_cast<int>(config.joints.size()) - config.extra_joints)),
        limits_(axis_rate_limits(config)) {
    for (int j = 0; j < joints_; ++j) {
      const auto& joint = config.joints[static_cast<std::size_t>(j)];
      if (j == 0) {
        limits_.push_back(joint_rate_limit(joint, {{0, 1.0}, {1, 1.0}}));
      } else if (j == 1) {
        limits_.push_back(joint_rate_limit(joint, {{0, 1.0}, {1, -1.0}}));
      } else {
        limits_.push_back(joint_rate_limit(joint, {{j, 1.0}}));
      }
    }
  }

  void forward(const JointArray& joints, AxisPose& axes) const noexcept override {
    axes[0] = 0.5 * (joints[0] + joints[1]);
    axes[1] = 0.5 * (joints[0] - joints[1]);
    for (int j = 2; j < joints_; ++j)
      axes[static_cast<std::size_t>(j)] = joints[static_cast<std::size_t>(j)];
  }

  void inverse(const AxisPose& axes, std::uint32_t axis_mask,
               JointArray& joints) const noexcept override {
    if ((axis_mask & kXY) != 0) {
      joints[0] = axes[0] + axes[1];
      joints[1] = axes[0] - axes[1];
    }
    for (int j = 2; j < joints_; ++j) {
      if ((axis_mask & (1u << j)) != 0)
        joints[static_cast<std::size_t>(j)] = axes[static_cast<std::size_t>(j)];
    }
  }

  std::uint32_t joints_of_axis(int axis) const noexcept override {
    if (axis == 0 || axis == 1) return kXY;
    return axis >= 2 && axis < joints_ ? 1u << axis : 0;
  }

  int axis_of_joint(int joint) const noexcept override {
    return joint >= 2 && joint < joints_ ? joint : -1;
  }

  std::span<const RateLimit> rate_limits() const noexcept override { return limits_; }
  std::uint32_t coupled_axes() const noexcept override { return kXY; }

 private:
  int joints_;  // the joints the kinematics drives (not the extra joints)
  std::vector<RateLimit> limits_;
};

}  // namespace

std::unique_ptr<const Kinematics> make_corexykins(const config::MachineConfig& config) {
  return std::make_unique<CoreXyKinematics>(config);
}

}  // namespace cncd::motion
