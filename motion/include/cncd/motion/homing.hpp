// Homing with LinuxCNC's semantics, run inside the servo period.
//
// HOME_SEARCH_VEL = HOME_LATCH_VEL = 0: the joint's current position becomes HOME_OFFSET
// without moving, then the joint moves to HOME. Otherwise the joint searches its home switch
// at HOME_SEARCH_VEL, backs off, latches the switch edge at HOME_LATCH_VEL (rising edge when
// both velocities have the same sign, falling edge otherwise), calls that point HOME_OFFSET
// and moves to HOME at HOME_FINAL_VEL. Redefining a joint's position never moves its motor:
// it changes the joint's motor offset (motor position = joint position + offset).
// Joints home in HOME_SEQUENCE order; joints sharing a sequence home together, and a
// negative HOME_SEQUENCE makes them start their final move together.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

// The servo loop's joints, in joint coordinates; homing reads and changes them.
struct JointIo {
  JointArray command{};       // commanded joint position
  JointArray feedback{};      // measured joint position
  JointArray motor_offset{};  // motor position = joint position + offset
  std::array<bool, kJoints> home_switch{};
  std::array<bool, kJoints> homed{};
};

class Homing {
 public:
  enum class Result : std::uint8_t { idle, running, finished, aborted, failed };

  // `switch_joints`: the joints whose driver reports a home switch.
  Homing(const config::MachineConfig& config, double period_s, std::uint32_t switch_joints);

  // RT. Starts homing the joints in `mask` (all ones: "home all", the joints that have a
  // HOME_SEQUENCE, or every joint when none has). Returns false, with the reason in fault(),
  // when a joint's homing configuration cannot be carried out; nothing moves then.
  CNCD_RT bool start(std::uint32_t mask, JointIo& io) noexcept;
  // RT. One servo period: advances every homing joint and moves on through the sequences.
  // `finished` and `aborted` are reported once, then `idle`.
  CNCD_RT Result update(JointIo& io) noexcept;
  // RT. Brings the homing joints to a controlled stop; update() reports `aborted` once they
  // stand still. The joints stay unhomed.
  CNCD_RT void abort() noexcept;
  // RT. Forgets any homing in progress at once (estop, machine off, fault).
  CNCD_RT void stop_now() noexcept;

  CNCD_RT bool active() const noexcept { return active_; }
  CNCD_RT bool stopping() const noexcept { return aborting_; }
  // True while joint `j` homes with HOME_IGNORE_LIMITS (its limit switch is its home switch).
  CNCD_RT bool ignores_limits(int j) const noexcept;
  // Why start() refused or update() failed.
  CNCD_RT const RtEvent& fault() const noexcept { return fault_; }

 private:
  enum class Phase : std::uint8_t {
    idle,
    waiting,          // in a later sequence
    initial_backoff,  // started on the switch: move off it at -search velocity
    search,           // towards the switch at search velocity
    latch_backoff,    // same-sign latch: off the switch again at -search velocity
    latch_rise,       // towards the switch at latch velocity, latch where it closes
    latch_fall,       // away from the switch at latch velocity, latch where it opens
    final_move,       // to HOME
  };
  // One joint's free move: along `direction` from `origin`, resting at both ends unless
  // stopped early (v_max = 0 brings it to rest at its acceleration limit).
  struct FreeMove {
    bool active = false;
    bool reached_end = false;
    double origin = 0;
    double direction = 1;
    double length = 0;
    double s = 0;
    double v = 0;
    double v_max = 0;
    double a = 0;
  };
  struct JointHoming {
    Phase phase = Phase::idle;
    bool move_started = false;  // the phase's move has begun
    double pause_s = 0;         // settling time before the phase's move
    FreeMove move;
  };

  CNCD_RT bool check_config(int j) noexcept;
  CNCD_RT void start_sequence(JointIo& io) noexcept;
  CNCD_RT bool step_joint(int j, JointIo& io) noexcept;  // false: failed, fault_ set
  CNCD_RT bool settle(int j) noexcept;
  CNCD_RT void enter(int j, Phase phase) noexcept;
  CNCD_RT void start_move(int j, const JointIo& io, double velocity, double target,
                          bool to_target) noexcept;
  CNCD_RT void set_position(int j, JointIo& io, double position) noexcept;
  CNCD_RT bool sync_ready(int j) const noexcept;
  CNCD_RT void fail(int j, const char* what) noexcept;  // `what`: a string literal

  const config::MachineConfig& config_;
  double period_s_;
  int joint_count_;
  std::uint32_t switch_joints_;
  std::array<JointHoming, kJoints> joints_{};
  std::uint32_t pending_ = 0;  // joints still to home, this sequence included
  int sequence_ = -1;          // sequence homing now, -1 = none
  bool active_ = false;
  bool aborting_ = false;
  RtEvent fault_;
};

}  // namespace cncd::motion
