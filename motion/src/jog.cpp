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

const char* jog_refusal(const config::MachineConfig& config, int axis, double position,
                        double direction, bool homed) noexcept {
  if (axis < 0 || axis >= kAxes || !config.axes[static_cast<std::size_t>(axis)].present)
    return "the machine has no such axis";
  if (!homed) return nullptr;
  const auto& limits = config.axes[static_cast<std::size_t>(axis)];
  if (direction > 0 && position >= limits.max_limit - 1e-9)
    return "the axis is at its maximum soft limit";
  if (direction < 0 && position <= limits.min_limit + 1e-9)
    return "the axis is at its minimum soft limit";
  return nullptr;
}

Jog::Jog(const config::MachineConfig& config) : config_(config) {
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
  if (const char* refusal = jog_refusal(config_, axis, position, direction, homed)) return refusal;
  if (const char* refusal = coupling_refusal(axis)) return refusal;
  const auto& limits = config_.axes[static_cast<std::size_t>(axis)];
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
  const double target = homed ? (direction > 0 ? limits.max_limit : limits.min_limit)
                              : position + direction * kUnlimited;
  begin(axis, position, target, speed);
  return nullptr;
}

const char* Jog::increment(int axis, double position, double distance, double speed,
                           bool homed) noexcept {
  const double direction = distance > 0 ? 1.0 : -1.0;
  if (const char* refusal = jog_refusal(config_, axis, position, direction, homed)) return refusal;
  if (axes_[static_cast<std::size_t>(axis)].active) return "the axis is jogging";
  if (const char* refusal = coupling_refusal(axis)) return refusal;
  const auto& limits = config_.axes[static_cast<std::size_t>(axis)];
  const double capped = std::min(std::abs(speed), max_velocity_[static_cast<std::size_t>(axis)]);
  if (!std::isfinite(capped) || capped <= 0) return "the jog speed must be above 0";
  if (!std::isfinite(distance) || distance == 0) return "the jog distance must not be 0";
  double target = position + distance;
  if (homed) target = std::clamp(target, limits.min_limit, limits.max_limit);
  begin(axis, position, target, capped);
  return nullptr;
}

void Jog::follow(int axis, double position, double target, double speed) noexcept {
  if (axis < 0 || axis >= kAxes) return;
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
  if (axis < 0 || axis >= kAxes) return;
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
  for (int axis = 0; axis < kAxes; ++axis)
    stop(axis);
}

void Jog::halt() noexcept {
  for (auto& j : axes_)
    j = AxisJog{};
}

std::uint32_t Jog::active_mask() const noexcept {
  std::uint32_t mask = 0;
  for (int axis = 0; axis < kAxes; ++axis) {
    if (axes_[static_cast<std::size_t>(axis)].active) mask |= 1u << axis;
  }
  return mask;
}

void Jog::update(AxisPose& pose, double dt) noexcept {
  for (int axis = 0; axis < kAxes; ++axis) {
    auto& j = axes_[static_cast<std::size_t>(axis)];
    if (!j.active) continue;
    double left = dt;
    const double a = max_acceleration_[static_cast<std::size_t>(axis)];
    const bool done = advance_profile(j.s, j.v, j.length, j.v_max, a, left);
    // At the end exactly on the target (the soft limit, when it is one), not a rounding off.
    pose[static_cast<std::size_t>(axis)] = done ? j.target : j.origin + j.direction * j.s;
    if (!done) continue;
    j.active = false;
    j.v = 0;
    if (j.pending) {
      j.pending = false;
      start(axis, pose[static_cast<std::size_t>(axis)], j.pending_velocity, j.pending_homed);
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
