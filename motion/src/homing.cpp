#include "cncd/motion/homing.hpp"

#include <algorithm>
#include <cmath>

#include "profile.hpp"

namespace cncd::motion {
namespace {

// Settling time before each homing move, as in LinuxCNC: the joint has stopped and the
// switch has stopped bouncing.
constexpr double kHomeDelayS = 0.1;

int sequence_of(const config::JointConfig& joint) noexcept {
  return std::max(0, joint.home_sequence);
}

bool immediate(const config::JointConfig& joint) noexcept {
  return joint.home_absolute_encoder || (joint.home_search_vel == 0 && joint.home_latch_vel == 0);
}

}  // namespace

Homing::Homing(const config::MachineConfig& config, double period_s, std::uint32_t switch_joints)
    : config_(config),
      period_s_(period_s),
      joint_count_(static_cast<int>(std::min<std::size_t>(config.joints.size(), kJoints))),
      switch_joints_(switch_joints) {}

bool Homing::ignores_limits(int j) const noexcept {
  return active_ && joints_[static_cast<std::size_t>(j)].phase != Phase::idle &&
         config_.joints[static_cast<std::size_t>(j)].home_ignore_limits;
}

void Homing::fail(int j, const char* what) noexcept {
  fault_ = RtEvent{};
  fault_.code = RtEvent::Code::homing_failed;
  fault_.joint = static_cast<std::int8_t>(j);
  fault_.words = what;
}

bool Homing::check_config(int j) noexcept {
  const auto& joint = config_.joints[static_cast<std::size_t>(j)];
  if (!(joint.max_velocity > 0) || !(joint.max_acceleration > 0)) {
    fail(j, "homing needs a positive MAX_VELOCITY and MAX_ACCELERATION");
    return false;
  }
  if (immediate(joint)) return true;
  if (joint.home_use_index) {
    fail(j, "index homing (HOME_USE_INDEX) is not supported");
  } else if (joint.home_search_vel == 0) {
    fail(j, "invalid homing config: a non-zero HOME_LATCH_VEL needs HOME_SEARCH_VEL");
  } else if (joint.home_latch_vel == 0) {
    fail(j, "invalid homing config: a non-zero HOME_SEARCH_VEL needs HOME_LATCH_VEL");
  } else if (!(switch_joints_ & (1u << j))) {
    fault_ = RtEvent{};
    fault_.code = RtEvent::Code::homing_needs_switch;
    fault_.joint = static_cast<std::int8_t>(j);
    drivers::copy_text(fault_.text, sizeof fault_.text, joint.driver.c_str());
  } else {
    return true;
  }
  return false;
}

bool Homing::start(std::uint32_t mask, JointIo& io) noexcept {
  fault_ = RtEvent{};
  if (active_) {
    fault_.code = RtEvent::Code::homing_in_progress;
    return false;
  }
  const std::uint32_t all = joint_count_ >= 32 ? ~0u : (1u << joint_count_) - 1;
  if (mask == ~0u) {
    std::uint32_t sequenced = 0;
    for (int j = 0; j < joint_count_; ++j) {
      if (config_.joints[static_cast<std::size_t>(j)].home_sequence >= 0) sequenced |= 1u << j;
    }
    mask = sequenced != 0 ? sequenced : all;
  }
  mask &= all;
  // Joints of a synchronised (negative) sequence always home together.
  for (int j = 0; j < joint_count_; ++j) {
    const auto& joint = config_.joints[static_cast<std::size_t>(j)];
    if (!(mask & (1u << j)) || !joint.home_sequence_sync) continue;
    for (int k = 0; k < joint_count_; ++k) {
      const auto& other = config_.joints[static_cast<std::size_t>(k)];
      if (sequence_of(other) == sequence_of(joint)) mask |= 1u << k;
    }
  }
  for (int j = 0; j < joint_count_; ++j) {
    if ((mask & (1u << j)) && !check_config(j)) return false;
  }
  if (mask == 0) return true;
  for (int j = 0; j < joint_count_; ++j) {
    if (!(mask & (1u << j))) continue;
    io.homed[static_cast<std::size_t>(j)] = false;
    joints_[static_cast<std::size_t>(j)] = JointHoming{};
    joints_[static_cast<std::size_t>(j)].phase = Phase::waiting;
  }
  pending_ = mask;
  active_ = true;
  aborting_ = false;
  start_sequence(io);
  return true;
}

void Homing::start_sequence(JointIo& io) noexcept {
  sequence_ = -1;
  for (int j = 0; j < joint_count_; ++j) {
    if (!(pending_ & (1u << j))) continue;
    const int seq = sequence_of(config_.joints[static_cast<std::size_t>(j)]);
    if (sequence_ < 0 || seq < sequence_) sequence_ = seq;
  }
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& joint = config_.joints[k];
    if (!(pending_ & (1u << j)) || sequence_of(joint) != sequence_) continue;
    if (joint.home_absolute_encoder) {
      // The encoder knows where the joint is: joint position = motor position + HOME_OFFSET.
      set_position(j, io, io.feedback[k] + io.motor_offset[k] + joint.home_offset);
      enter(j, Phase::final_move);
    } else if (immediate(joint)) {
      set_position(j, io, joint.home_offset);
      enter(j, Phase::final_move);
    } else {
      enter(j, io.home_switch[k] ? Phase::initial_backoff : Phase::search);
    }
  }
}

void Homing::enter(int j, Phase phase) noexcept {
  auto& h = joints_[static_cast<std::size_t>(j)];
  h.phase = phase;
  h.move_started = false;
  h.pause_s = 0;
}

bool Homing::settle(int j) noexcept {
  auto& h = joints_[static_cast<std::size_t>(j)];
  if (h.move.active) {
    h.pause_s = 0;
    return false;
  }
  if (h.pause_s + 1e-9 < kHomeDelayS) {
    h.pause_s += period_s_;
    return false;
  }
  return true;
}

void Homing::start_move(int j, const JointIo& io, double velocity, double target,
                        bool to_target) noexcept {
  const auto k = static_cast<std::size_t>(j);
  const auto& joint = config_.joints[k];
  auto& h = joints_[k];
  FreeMove& m = h.move;
  m = FreeMove{};
  m.origin = io.command[k];
  m.a = joint.max_acceleration;
  m.v_max = std::min(std::abs(velocity), joint.max_velocity);
  if (to_target) {
    m.direction = target >= m.origin ? 1.0 : -1.0;
    m.length = std::abs(target - m.origin);
  } else {
    // A search runs up to twice the joint's travel; the switch is meant to end it sooner.
    m.direction = velocity >= 0 ? 1.0 : -1.0;
    m.length = std::min(2.0 * (joint.max_limit - joint.min_limit), 1e9);
  }
  m.active = m.length > 0;
  m.reached_end = !m.active;
  h.move_started = true;
}

void Homing::set_position(int j, JointIo& io, double position) noexcept {
  const auto k = static_cast<std::size_t>(j);
  const double shift = position - io.feedback[k];
  io.command[k] += shift;
  io.feedback[k] += shift;
  io.motor_offset[k] -= shift;
  joints_[k].move.origin += shift;
}

bool Homing::sync_ready(int j) const noexcept {
  if (!config_.joints[static_cast<std::size_t>(j)].home_sequence_sync) return true;
  for (int k = 0; k < joint_count_; ++k) {
    const auto& other = joints_[static_cast<std::size_t>(k)];
    if (other.phase == Phase::idle || other.phase == Phase::waiting) continue;
    if (other.phase != Phase::final_move) return false;
    if (!other.move_started && other.move.active) return false;
  }
  return true;
}

bool Homing::step_joint(int j, JointIo& io) noexcept {
  const auto k = static_cast<std::size_t>(j);
  const auto& joint = config_.joints[k];
  auto& h = joints_[k];
  const bool on_switch = io.home_switch[k];
  const double search_vel = joint.home_search_vel;
  const double latch_vel = joint.home_latch_vel;
  switch (h.phase) {
    case Phase::idle:
    case Phase::waiting:
      break;
    case Phase::initial_backoff:
      if (!h.move_started) {
        if (settle(j)) start_move(j, io, -search_vel, 0, false);
      } else if (!on_switch) {
        h.move.v_max = 0;
        enter(j, Phase::search);
      }
      break;
    case Phase::search:
      if (!h.move_started) {
        if (!settle(j)) break;
        if (on_switch) {
          enter(j, Phase::initial_backoff);
        } else {
          start_move(j, io, search_vel, 0, false);
        }
      } else if (on_switch) {
        // Roughly home: name the position now, refine it on the latch pass.
        h.move.v_max = 0;
        set_position(j, io, joint.home_offset);
        enter(j, search_vel * latch_vel > 0 ? Phase::latch_backoff : Phase::latch_fall);
      }
      break;
    case Phase::latch_backoff:
      if (!h.move_started) {
        if (!settle(j)) break;
        if (!on_switch) {
          fail(j, "home switch opened before the backoff move");
          return false;
        }
        start_move(j, io, -search_vel, 0, false);
      } else if (!on_switch) {
        h.move.v_max = 0;
        enter(j, Phase::latch_rise);
      }
      break;
    case Phase::latch_rise:
    case Phase::latch_fall: {
      const bool rise = h.phase == Phase::latch_rise;
      if (!h.move_started) {
        if (!settle(j)) break;
        if (on_switch == rise) {
          fail(j, rise ? "home switch closed before the latch move"
                       : "home switch opened before the latch move");
          return false;
        }
        start_move(j, io, latch_vel, 0, false);
      } else if (on_switch == rise) {
        h.move.v_max = 0;
        set_position(j, io, joint.home_offset);
        enter(j, Phase::final_move);
      }
      break;
    }
    case Phase::final_move:
      if (!h.move_started) {
        if (h.move.active || !sync_ready(j)) break;
        const double v = joint.home_final_vel > 0 ? joint.home_final_vel : joint.max_velocity;
        start_move(j, io, v, joint.home, true);
      } else if (!h.move.active) {
        io.command[k] = joint.home;
        io.homed[k] = true;
        h = JointHoming{};
        pending_ &= ~(1u << j);
        return true;
      }
      break;
  }
  if (h.move_started && h.phase != Phase::final_move && h.move.reached_end) {
    fail(j, "home switch not found within twice the joint's travel");
    return false;
  }
  return true;
}

Homing::Result Homing::update(JointIo& io) noexcept {
  if (!active_) return Result::idle;
  if (!aborting_) {
    for (int j = 0; j < joint_count_; ++j) {
      if (!step_joint(j, io)) {
        stop_now();
        return Result::failed;
      }
    }
  }
  bool moving = false;
  for (int j = 0; j < joint_count_; ++j) {
    auto& m = joints_[static_cast<std::size_t>(j)].move;
    if (!m.active) continue;
    double dt = period_s_;
    if (advance_profile(m.s, m.v, m.length, m.v_max, m.a, dt)) {
      m.active = false;
      m.reached_end = true;
    } else if (m.v_max == 0 && at_rest(m.v)) {
      m.active = false;
    }
    io.command[static_cast<std::size_t>(j)] = m.origin + m.direction * m.s;
    moving = moving || m.active;
  }
  if (aborting_) {
    if (moving) return Result::running;
    stop_now();
    return Result::aborted;
  }
  if (pending_ == 0) {
    stop_now();
    return Result::finished;
  }
  bool sequence_busy = false;
  for (const auto& h : joints_)
    sequence_busy = sequence_busy || (h.phase != Phase::idle && h.phase != Phase::waiting);
  if (!sequence_busy) start_sequence(io);
  return Result::running;
}

void Homing::abort() noexcept {
  if (!active_) return;
  aborting_ = true;
  for (auto& h : joints_) {
    h.move.v_max = 0;
    h.phase = Phase::idle;
  }
}

void Homing::stop_now() noexcept {
  for (auto& h : joints_)
    h = JointHoming{};
  pending_ = 0;
  sequence_ = -1;
  active_ = false;
  aborting_ = false;
}

}  // namespace cncd::motion
