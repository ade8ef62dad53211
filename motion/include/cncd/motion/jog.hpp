// Jogging: continuous and incremental moves of single axes, each a trapezoid within the axis's
// MAX_VELOCITY and MAX_ACCELERATION, and those of the joints it moves, that ends at the soft
// limit on a homed axis. Axes that share a joint (corexy's X and Y) jog one at a time. The same
// moves of single joints (joint mode, as LinuxCNC jogs a joint before homing): within the
// joint's own [JOINT_n] limits, the axes following by the forward kinematics.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

// Why a jog of `axis` from `position` in `direction` (+1 or -1) cannot start, or nullptr.
// A homed axis may not jog at or beyond its soft limit in that direction. Any thread.
CNCD_RT const char* jog_refusal(const config::MachineConfig& config, int axis, double position,
                                double direction, bool homed) noexcept;
// The same for a jog of joint `joint` in joint mode, against its [JOINT_n] soft limits.
CNCD_RT const char* joint_jog_refusal(const config::MachineConfig& config, int joint,
                                      double position, double direction, bool homed) noexcept;

class Kinematics;

// Whether a joint-mode jog of homed joint `joint` keeps every axis within its soft limits: the
// joint is its axis's only joint, or no axis moves with it (an extra joint). Any thread.
CNCD_RT bool homed_joint_may_jog(const Kinematics& kins, int joint) noexcept;
// Whether a joint of `axis` stands apart from where the axis, at the joints' forward position,
// puts it (a gantry joint jogged alone): a jog of the axis would make it jump there at once.
CNCD_RT bool joints_apart_from_axis(const Kinematics& kins, const JointArray& joints,
                                    int joint_count, int axis) noexcept;
// Why a homed joint may not jog alone.
inline constexpr const char* kHomedJointMovesWithAxis =
    "the joint is homed and moves with its axis: jog the axis";

inline constexpr const char* kJointsApartForJog =
    "a joint of the axis stands apart from it (jogged alone): home the axis, or jog that joint "
    "back to its twin";

// Jog targets as the controller and its clients number them: an axis index
// (config::axis_index), or kJointJogBase + a joint's number for a joint-mode jog.
inline constexpr int kJointJogBase = kAxes;
inline constexpr int kJogTargets = kAxes + kJoints;

class Jog {
 public:
  // What the jogs move: the axes (indexes as config::axis_index) or the joints.
  enum class Space : std::uint8_t { axes, joints };
  static constexpr int kSlots = kJoints > kAxes ? kJoints : kAxes;

  explicit Jog(const config::MachineConfig& config, Space space = Space::axes);

  // RT (servo thread, as every method). Continuous jog of `axis` from `position` at `velocity`
  // units/s (its sign is the direction, its size capped at MAX_VELOCITY), on a homed axis up
  // to the soft limit. An axis jogging the same way takes the new speed; one jogging the other
  // way comes to rest first. Returns nullptr or why it is refused.
  CNCD_RT const char* start(int axis, double position, double velocity, bool homed) noexcept;
  // RT. Moves `axis` by `distance` (on a homed axis no further than the soft limit) at up to
  // `speed` units/s. Refused while the axis jogs.
  CNCD_RT const char* increment(int axis, double position, double distance, double speed,
                                bool homed) noexcept;
  // RT. Moves `axis` toward `target` at up to `speed`, called again as the target moves (the
  // MPG's summed detents): a target further along the way the axis moves extends its move; one
  // it can no longer reach without overshooting (behind it, or within its stopping distance)
  // brings it to rest, and the next call turns it back. The caller clips the target at the soft
  // limits. Ends exactly on the target.
  CNCD_RT void follow(int axis, double position, double target, double speed) noexcept;
  // RT. Controlled stop at the axis's MAX_ACCELERATION.
  CNCD_RT void stop(int axis) noexcept;
  CNCD_RT void stop_all() noexcept;
  // RT. Forgets every jog at once (estop, drives off): the caller holds the positions.
  CNCD_RT void halt() noexcept;
  CNCD_RT bool active() const noexcept { return active_mask() != 0; }
  // Bit i set: axis i is jogging.
  CNCD_RT std::uint32_t active_mask() const noexcept;
  // RT. Advances every jogging axis (joint) by `dt` seconds and writes its position into
  // `pose` (`joints`).
  CNCD_RT void update(AxisPose& pose, double dt) noexcept { update(pose.data(), kAxes, dt); }
  CNCD_RT void update(JointArray& joints, double dt) noexcept {
    update(joints.data(), kJoints, dt);
  }
  // Speed along the combined direction of the jogging axes, units/s.
  CNCD_RT double speed() const noexcept;

 private:
  struct AxisJog {
    bool active = false;
    double origin = 0;     // where this leg started
    double direction = 1;  // +1 / -1
    double length = 0;     // distance from origin to the target
    double target = 0;     // where it comes to rest (absent a stop)
    double s = 0;          // distance covered
    double v = 0;          // speed, >= 0
    double v_max = 0;
    bool pending = false;  // a reversal waits for the axis to come to rest
    double pending_velocity = 0;
    bool pending_homed = false;
  };
  CNCD_RT void begin(int axis, double position, double target, double speed) noexcept;
  CNCD_RT void update(double* positions, int count, double dt) noexcept;
  CNCD_RT const char* refusal(int index, double position, double direction,
                              bool homed) const noexcept;
  // Soft limits of slot `index` (an axis's or a joint's).
  CNCD_RT double min_limit(int index) const noexcept;
  CNCD_RT double max_limit(int index) const noexcept;
  // Why `axis` may not start now while others jog, or nullptr.
  CNCD_RT const char* coupling_refusal(int axis) const noexcept;

  const config::MachineConfig& config_;
  Space space_;
  int count_;                  // kAxes or the machine's joints
  std::uint32_t coupled_ = 0;  // Kinematics::coupled_axes() (none among joints)
  // Per slot: the speed and acceleration its jogs keep within; for an axis the tightest of the
  // axis's own and those of the joints it moves.
  std::array<double, kSlots> max_velocity_{};
  std::array<double, kSlots> max_acceleration_{};
  std::array<AxisJog, kSlots> axes_{};
};

}  // namespace cncd::motion
