// xyzac-trt-kins and xyzbc-trt-kins: a rotary table (C) on a tilting cradle (A about X, or B
// about Y), the spindle moving in X, Y and Z. The joints drive X Y Z A C (X Y Z B C) one to
// one, as LinuxCNC's identity mode does; under TCP the part's frame turns with the table and
// the tool tip is programmed in it (docs/kinematics.md has the geometry drawn):
//
//   machine = T(tilt) (C(c) (part - t z - R) + R - P) + P + t z
//
// R is the point where the C axis crosses ([KINS] X/Y/Z_ROT_POINT), P = R + the offsets from
// the C axis to the tilting axis (Y_OFFSET and Z_OFFSET for A, X_OFFSET and Z_OFFSET for B), t
// the tool's length along Z (the G43 length in force, as LinuxCNC nets motion.tooloffset.z to
// the module's tool-offset pin; [KINS] TOOL_OFFSET while that is 0), C(c) the table's turn by
// c about +Z and T the cradle's by the tilt angle about +X (+Y for B), counterclockwise seen
// from the axis's positive end. At every rotary at 0 the two frames are the same, whatever t.
#include <cmath>
#include <numbers>
#include <vector>

#include "kins_modules.hpp"

namespace cncd::motion {
namespace {

constexpr int kX = 0, kY = 1, kZ = 2, kA = 3, kB = 4, kC = 5;

struct Vec {
  double x = 0, y = 0, z = 0;
};

// `v` turned by `angle` (radians, counterclockwise seen from the axis's positive end) about
// the axis through the origin along X (0), Y (1) or Z (2).
Vec turn(const Vec& v, int axis, double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  switch (axis) {
    case 0:
      return {v.x, c * v.y - s * v.z, s * v.y + c * v.z};
    case 1:
      return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
    default:
      return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
  }
}

Vec operator+(const Vec& a, const Vec& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec operator-(const Vec& a, const Vec& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}

double radians_per_unit(config::AngularUnits units) {
  switch (units) {
    case config::AngularUnits::radian:
      return 1.0;
    case config::AngularUnits::grad:
      return std::numbers::pi / 200.0;
    default:
      return std::numbers::pi / 180.0;
  }
}

class TableRotaryKinematics final : public Kinematics {
 public:
  explicit TableRotaryKinematics(const config::MachineConfig& config)
      : identity_(make_trivkins(config)),
        tilt_axis_(config.kinematics == "xyzbc-trt-kins" ? kB : kA),
        to_radians_(radians_per_unit(config.angular_units)),
        limits_(axis_rate_limits(config)) {
    const config::TableRotaryConfig& t = config.table_rotary;
    c_point_ = {t.x_rot_point, t.y_rot_point, t.z_rot_point};
    tilt_point_ = c_point_ + (tilt_axis_ == kA ? Vec{0, t.y_offset, t.z_offset}
                                               : Vec{t.x_offset, 0, t.z_offset});
    tool_offset_ = t.tool_offset;
    // Each joint moves as its axis and within its own limits too.
    for (std::size_t j = 0; j < config.joints.size() && j < static_cast<std::size_t>(kJoints);
         ++j) {
      const int axis = identity_->axis_of_joint(static_cast<int>(j));
      if (axis >= 0) limits_.push_back(joint_rate_limit(config.joints[j], {{axis, 1.0}}));
    }
  }

  void forward(const JointArray& joints, AxisPose& axes) const noexcept override {
    identity_->forward(joints, axes);
  }
  void inverse(const AxisPose& axes, std::uint32_t axis_mask,
               JointArray& joints) const noexcept override {
    identity_->inverse(axes, axis_mask, joints);
  }
  std::uint32_t joints_of_axis(int axis) const noexcept override {
    return identity_->joints_of_axis(axis);
  }
  int axis_of_joint(int joint) const noexcept override { return identity_->axis_of_joint(joint); }
  std::span<const RateLimit> rate_limits() const noexcept override { return limits_; }
  std::uint32_t coupled_axes() const noexcept override { return 0; }

  bool has_tcp() const noexcept override { return true; }

  void tcp_forward(const AxisPose& machine, double tool_length,
                   AxisPose& part) const noexcept override {
    part = machine;
    const Vec tool = tool_along_z(tool_length);
    const Vec tip = Vec{machine[kX], machine[kY], machine[kZ]} - tool;
    const Vec on_cradle = turn(tip - tilt_point_, tilt_index(), -tilt(machine)) + tilt_point_;
    const Vec p = turn(on_cradle - c_point_, 2, -c(machine)) + c_point_ + tool;
    part[kX] = p.x;
    part[kY] = p.y;
    part[kZ] = p.z;
  }

  void tcp_inverse(const AxisPose& part, double tool_length,
                   AxisPose& machine) const noexcept override {
    machine = part;
    const Vec tool = tool_along_z(tool_length);
    const Vec tip = Vec{part[kX], part[kY], part[kZ]} - tool;
    const Vec on_cradle = turn(tip - c_point_, 2, c(part)) + c_point_;
    const Vec m = turn(on_cradle - tilt_point_, tilt_index(), tilt(part)) + tilt_point_ + tool;
    machine[kX] = m.x;
    machine[kY] = m.y;
    machine[kZ] = m.z;
  }

 private:
  // t z: the G43 length in force, or TOOL_OFFSET without one.
  Vec tool_along_z(double tool_length) const noexcept {
    return {0, 0, tool_length != 0 ? tool_length : tool_offset_};
  }
  int tilt_index() const noexcept { return tilt_axis_ == kA ? 0 : 1; }
  double tilt(const AxisPose& pose) const noexcept {
    return pose[static_cast<std::size_t>(tilt_axis_)] * to_radians_;
  }
  double c(const AxisPose& pose) const noexcept { return pose[kC] * to_radians_; }

  std::unique_ptr<const Kinematics> identity_;  // the joint map: joint n drives its axis
  int tilt_axis_;                               // kA or kB
  double to_radians_;                           // per machine angular unit
  Vec c_point_;                                 // R
  Vec tilt_point_;                              // P
  double tool_offset_ = 0;                      // [KINS] TOOL_OFFSET
  std::vector<RateLimit> limits_;
};

}  // namespace

std::unique_ptr<const Kinematics> make_trtkins(const config::MachineConfig& config) {
  return std::make_unique<TableRotaryKinematics>(config);
}

}  // namespace cncd::motion
