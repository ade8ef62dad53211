#include "cncd/motion/jog.hpp"

#include <algorithm>
#include <cmath>

#include "cncd/motion/kinematics.hpp"
#include "profile.hpp"

namespace cncd::motion {
namespace {
// An unhomed axis has no soft limits: a continuous jog runs until it is stopped.
constexpr double kUnlimited = 1e9;
}  // namespace

namespace {

const char* limit_refusal(double position, double direction, double min_limit, double max_limit,
                          const char* at_max, const char* at_min) noexcept {
  if (direction > 0 && position >= max_limit - 1e-9) return at_max;
  if (direction < 0 && position <= min_limit + 1e-9) return at_min;
  return nullptr;
}

}  // namespace

const char* jog_refusal(const config::MachineConfig& config, int axis, double position,
                        double direction, bool homed) noexcept {
  if (axis < 0 || axis >= kAxes || !config.axes[static_cast<std::size_t>(axis)].present)
    return "the machine has no such axis";
  if (!homed) return nullptr;
  const auto& limits = config.axes[static_cast<std::size_t>(axis)];
  return limit_refusal(position, direction, limits.min_limit, limits.max_limit,
                       "the axis is at its maximum soft limit",
                       "the axis is at its minimum soft limit");
}

const char* joint_jog_refusal(const config::MachineConfig& config, int joint, double position,
                              double direction, bool homed) noexcept {
  if (joint < 0 || static_cast<std::size_t>(joint) >= config.joints.size())
    return "the machine has no such joint";
  if (!homed) return nullptr;
  const auto& limits = config.joints[static_cast<std::size_t>(joint)];
  return limit_refusal(position, direction, limits.min_limit, limits.max_limit,
                       "the joint is at its maximum soft limit",
                       "the joint is at its minimum soft limit");
}

bool homed_joint_may_jog(const Kinematics& kins, int joint) noexcept {
  for (int axis = 0; axis < kAxes; ++axis) {
    const std::uint32_t joints = kins.joints_of_axis(axis);
    if ((joints & (1u << joint)) == 0) continue;
    // A gantry's joint leaves its twin behind; corexy's motor moves two axes.
    if (joints != (1u << joint) || kins.axis_of_joint(joint) != axis) return false;
  }
  return true;
}

bool joints_apart_from_axis(const Kinematics& kins, const JointArray& joints, int joint_count,
                            int axis) noexcept {
  AxisPose pose{};
  kins.forward(joints, pose);
  JointArray placed = joints;
  kins.inverse(pose, 1u << axis, placed);
  for (int j = 0; j < joint_count; ++j) {
    const auto k = static_cast<std::size_t>(j);
    if (std::abs(placed[k] - joints[k]) > 1e-6) return true;
  }
  return false;
}

Jog::Jog(const config::MachineConfig& config, Space space)
    : config_(config),
      space_(space),
      count_(space == Space::axes ? kAxes
                                  : std::min(kJoints, static_cast<int>(config.joints.size()))) {
  if (space == Space::joints) {
    for (int joint = 0; joint < count_; ++joint) {
      const auto k = static_cast<std::size_t>(joint);
      max_velocity_[k] = config.joints[k].max_velocity;
      max_acceleration_[k] = config.joints[k].max_acceleration;
    }
    return;
  }
  const auto kins = make_kinematics(config);
  coupled_ = kins->coupled_axes();
  for (int axis = 0; axis < kAxes; ++axis) {
    const auto k = static_cast<std::size_t>(axis);
    max_velocity_[k] = config.axes[k].max_velocity;
    max_acceleration_[k] = config.axes[k].max_acceleration;
    for (const RateLimit& limit : kins->rate_limits()) {
      const double share = std::abs(limit.coefficient(axis));
      if (share <= 0) continue;
      max_velocity_[k] = std::min(max_velocity_[k], limit.max_velocity / share);
      max_acceleration_[k] = std::min(max_acceleration_[k], limit.max_acceleration / share);
    }
  }
}

const char* Jog::refusal(int index, double position, double direction, bool homed) const noexcept {
  return space_ == Space::axes ? jog_refusal(config_, index, position, direction, homed)
                               : joint_jog_refusal(config_, index, position, direction, homed);
}

double Jog::min_limit(int index) const noexcept {
  const auto k = static_cast<std::size_t>(index);
  return space_ == Space::axes ? config_.axes[k].min_limit : config_.joints[k].min_limit;
}

double Jog::max_limit(int index) const noexcept {
  const auto k = static_cast<std::size_t>(index);
  return space_ == Space::axes ? config_.axes[k].max_limit : config_.joints[k].max_limit;
}

const char* Jog::coupling_refusal(int axis) const noexcept {
  const std::uint32_t others = active_mask() & ~(1u << axis);
  if ((coupled_ & (1u << axis)) != 0 && (coupled_ & others) != 0)
    return "the axis shares a motor with a jogging axis: jog them one at a time";
  return nullptr;
}

void Jog::begin(int axis, double position, double target, double speed) noexcept {
  auto& j = axes_[static_cast<std::size_t>(axis)];
  const double direction = target >= position ? 1.0 : -1.0;
  // Same way: carry on from the current speed; from rest otherwise.
  const bool keep = j.active && j.direction == direction;
  j.v = keep ? j.v : 0;
  j.active = true;
  j.origin = position;
  j.direction = direction;
  j.target = target;
  j.length = std::abs(target - position);
  j.s = 0;
  j.v_max = speed;
}

const char* Jog::start(int axis, double position, double velocity, bool homed) noexcept {
  const double direction = velocity > 0 ? 1.0 : -1.0;
  if (const char* why = refusal(axis, position, direction, homed)) return why;
  if (const char* why = coupling_refusal(axis)) return why;
  const double speed = std::min(std::abs(velocity), max_velocity_[static_cast<std::size_t>(axis)]);
  if (!std::isfinite(speed) || speed <= 0) return "the jog speed must be above 0";
  auto& j = axes_[static_cast<std::size_t>(axis)];
  if (j.active && j.direction != direction && j.v > 0) {
    stop(axis);
    j.pending = true;
    j.pending_velocity = direction * speed;
    j.pending_homed = homed;
    return nullptr;
  }
  j.pending = false;
  const double target = homed ? (direction > 0 ? max_limit(axis) : min_limit(axis))
                              : position + direction * kUnlimited;
  begin(axis, position, target, speed);
  return nullptr;
}

const char* Jog::increment(int axis, double position, double distance, double speed,
                           bool homed) noexcept {
  const double direction = distance > 0 ? 1.0 : -1.0;
  if (const char* why = refusal(axis, position, direction, homed)) return why;
  if (axes_[static_cast<std::size_t>(axis)].active)
    return space_ == Space::axes ? "the axis is jogging" : "the joint is jogging";
  if (const char* why = coupling_refusal(axis)) return why;
  const double capped = std::min(std::abs(speed), max_velocity_[static_cast<std::size_t>(axis)]);
  if (!std::isfinite(capped) || capped <= 0) return "the jog speed must be above 0";
  if (!std::isfinite(distance) || distance == 0) return "the jog distance must not be 0";
  double target = position + distance;
  if (homed) target = std::clamp(target, min_limit(axis), max_limit(axis));
  begin(axis, position, target, capped);
  return nullptr;
}

void Jog::follow(int axis, double position, double target, double speed) noexcept {
  if (axis < 0 || axis >= count_) return;
  auto& j = axes_[static_cast<std::size_t>(axis)];
  const double capped = std::min(speed, max_velocity_[static_cast<std::size_t>(axis)]);
  if (!j.active) {
    if (target != position && capped > 0) begin(axis, position, target, capped);
    return;
  }
  j.pending = false;
  const double a = max_acceleration_[static_cast<std::size_t>(axis)];
  const double ahead = j.direction * (target - j.origin);
  if (ahead >= j.s + j.v * j.v / (2.0 * a)) {
    j.length = ahead;
    j.target = target;
    j.v_max = capped;
  } else {
    stop(axis);
  }
}

void Jog::stop(int axis) noexcept {
  if (axis < 0 || axis >= count_) return;
  auto& j = axes_[static_cast<std::size_t>(axis)];
  j.pending = false;
  if (!j.active) return;
  const double a = max_acceleration_[static_cast<std::size_t>(axis)];
  // The shortest stop the acceleration allows, unless the target comes first.
  const double stop_length = j.s + j.v * j.v / (2.0 * a);
  if (stop_length < j.length) {
    j.length = stop_length;
    j.target = j.origin + j.direction * stop_length;
  }
}

void Jog::stop_all() noexcept {
  for (int axis = 0; axis < count_; ++axis)
    stop(axis);
}

void Jog::halt() noexcept {
  for (auto& j : axes_)
    j = AxisJog{};
}

std::uint32_t Jog::active_mask() const noexcept {
  std::uint32_t mask = 0;
  for (int axis = 0; axis < count_; ++axis) {
    if (axes_[static_cast<std::size_t>(axis)].active) mask |= 1u << axis;
  }
  return mask;
}

void Jog::update(double* pose, int count, double dt) noexcept {
  for (int axis = 0; axis < std::min(count, count_); ++axis) {
    auto& j = axes_[static_cast<std::size_t>(axis)];
    if (!j.active) continue;
    double left = dt;
    const double a = max_acceleration_[static_cast<std::size_t>(axis)];
    const bool done = advance_profile(j.s, j.v, j.length, j.v_max, a, left);
    // At the end exactly on the target (the soft limit, when it is one), not a rounding off.
    pose[axis] = done ? j.target : j.origin + j.direction * j.s;
    if (!done) continue;
    j.active = false;
    j.v = 0;
    if (j.pending) {
      j.pending = false;
      start(axis, pose[axis], j.pending_velocity, j.pending_homed);
    }
  }
}

double Jog::speed() const noexcept {
  double sum = 0;
  for (const auto& j : axes_) {
    if (j.active) sum += j.v * j.v;
  }
  return std::sqrt(sum);
}

}  // namespace cncd::motion
