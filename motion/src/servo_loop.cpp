#include "cncd/motion/servo_loop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace cncd::motion {
namespace {

// Advances (s, v) along the time-optimal profile that comes to rest exactly at `length`,
// limited by speed `v_max` (0 = come to a stop and hold) and acceleration `a`, for up to `dt`
// seconds. The profile is piecewise constant acceleration, so positions sampled from it at any
// times have second differences within `a`. Returns true when the end is reached; `dt` is then
// the time left over. RT-safe.
bool advance_profile(double& s, double& v, double length, double v_max, double a,
                     double& dt) noexcept {
  for (int phase = 0; phase < 8 && dt > 0; ++phase) {
    const double d = length - s;
    if (d <= 1e-12) {
      s = length;
      v = 0;
      return true;
    }
    const double stop_sq = 2.0 * a * d;
    if (v * v >= stop_sq - 1e-9 * (1.0 + v * v)) {
      // On the braking curve: brake to rest exactly at the end.
      if (v <= 0) {
        s = length;
        return true;
      }
      const double brake = v * v / (2.0 * d);
      const double t_stop = v / brake;
      if (t_stop <= dt) {
        s = length;
        v = 0;
        dt -= t_stop;
        return true;
      }
      s += v * dt - 0.5 * brake * dt * dt;
      v -= brake * dt;
      dt = 0;
      return false;
    }
    double accel;
    double duration;
    if (v > v_max + 1e-12) {
      accel = -a;  // slow down to the (lowered) limit
      duration = (v - v_max) / a;
    } else {
      const double peak = std::sqrt(0.5 * (stop_sq + v * v));
      const double target = std::min(v_max, peak);
      if (target > v + 1e-12) {
        accel = a;
        duration = (target - v) / a;
      } else if (v <= 0) {
        return false;  // holding at rest
      } else {
        accel = 0;  // cruise until the braking curve
        duration = (d - v * v / (2.0 * a)) / v;
      }
    }
    const double step = std::min(std::max(duration, 0.0), dt);
    s += v * step + 0.5 * accel * step * step;
    v = std::max(0.0, v + accel * step);
    dt -= step;
    if (s > length) s = length;
  }
  return false;
}

}  // namespace

ServoLoop::ServoLoop(const config::MachineConfig& config, std::vector<DriverBinding> drivers)
    : config_(config),
      drivers_(std::move(drivers)),
      period_s_(static_cast<double>(config.servo_period_ns) * 1e-9),
      joint_count_(static_cast<int>(std::min<std::size_t>(config.joints.size(), kJoints))) {
  for (int j = 0; j < joint_count_; ++j) {
    const int axis = config::axis_index(config.joints[static_cast<std::size_t>(j)].axis);
    joint_axis_[static_cast<std::size_t>(j)] = axis;
  }
  status_.joint_count = joint_count_;
  published_.store(status_);
}

void ServoLoop::set_rt_flags(bool realtime, bool memory_locked) noexcept {
  status_.rt.realtime = realtime;
  status_.rt.memory_locked = memory_locked;
}

void ServoLoop::post(Event::Level level, const char* text) noexcept {
  Event event;
  event.level = level;
  std::snprintf(event.text, sizeof event.text, "%s", text);
  events_.push(event);  // a full ring drops the event rather than wait
}

void ServoLoop::latch_fault(const char* reason) noexcept {
  if (status_.fault_reason[0] == '\0') {
    std::snprintf(status_.fault_reason, sizeof status_.fault_reason, "%s", reason);
    post(Event::Level::fault, reason);
  }
  stop_now(status_.machine == MachineState::estop ? MachineState::estop : MachineState::off,
           nullptr);
}

void ServoLoop::flush_queue() noexcept {
  Segment dropped;
  if (has_active_) ++status_.segments_done;
  has_active_ = false;
  while (segments_.pop(dropped))
    ++status_.segments_done;
  path_s_ = 0;
  path_v_ = 0;
  pause_requested_ = false;
  abort_requested_ = false;
}

void ServoLoop::stop_now(MachineState next, const char* reason) noexcept {
  flush_queue();
  for (auto& h : homing_)
    h = JointMotion{};
  home_pending_ = 0;
  home_sequence_ = -1;
  status_.machine = next;
  status_.motion = MotionState::idle;
  status_.velocity = 0;
  if (reason != nullptr) post(Event::Level::warning, reason);
}

void ServoLoop::apply(const Command& command) noexcept {
  switch (command.kind) {
    case Command::Kind::estop:
      if (status_.machine != MachineState::estop) stop_now(MachineState::estop, "estop");
      break;
    case Command::Kind::reset_estop:
      if (status_.machine == MachineState::estop) {
        status_.machine = MachineState::off;
        status_.fault_reason[0] = '\0';
        status_.joint_fault = {};
      }
      break;
    case Command::Kind::on:
      if (status_.machine == MachineState::off) {
        status_.machine = MachineState::on;
        status_.fault_reason[0] = '\0';
        status_.joint_fault = {};
        sync_axes_from_joints();
      }
      break;
    case Command::Kind::off:
      if (status_.machine == MachineState::on) stop_now(MachineState::off, nullptr);
      break;
    case Command::Kind::home: {
      if (status_.machine != MachineState::on || has_active_ || home_pending_ != 0) break;
      std::uint32_t mask = command.joint_mask;
      if (mask == 0xFFFFFFFFu) {
        // "Home all" homes the joints that have a HOME_SEQUENCE, or every joint when none has.
        std::uint32_t sequenced = 0;
        for (int j = 0; j < joint_count_; ++j) {
          if (config_.joints[static_cast<std::size_t>(j)].home_sequence >= 0) sequenced |= 1u << j;
        }
        mask = sequenced != 0 ? sequenced : (1u << joint_count_) - 1;
      }
      home_pending_ = mask & ((1u << joint_count_) - 1);
      for (int j = 0; j < joint_count_; ++j) {
        if (home_pending_ & (1u << j)) status_.homed[static_cast<std::size_t>(j)] = false;
      }
      home_sequence_ = -1;
      start_home_sequence();
      break;
    }
    case Command::Kind::abort:
      if (has_active_ || segments_.size() > 0) abort_requested_ = true;
      for (auto& h : homing_)
        h.active = false;
      if (home_pending_ != 0) {
        home_pending_ = 0;
        home_sequence_ = -1;
        post(Event::Level::warning, "homing aborted");
      }
      break;
    case Command::Kind::pause:
      pause_requested_ = true;
      break;
    case Command::Kind::resume:
      pause_requested_ = false;
      break;
  }
}

void ServoLoop::start_home_sequence() noexcept {
  // The lowest sequence number among the joints still to home goes next; joints sharing a
  // number home together.
  int next = -1;
  for (int j = 0; j < joint_count_; ++j) {
    if (!(home_pending_ & (1u << j))) continue;
    const int seq = std::max(0, config_.joints[static_cast<std::size_t>(j)].home_sequence);
    if (next < 0 || seq < next) next = seq;
  }
  home_sequence_ = next;
  if (next < 0) return;
  for (int j = 0; j < joint_count_; ++j) {
    if (!(home_pending_ & (1u << j))) continue;
    const auto& joint = config_.joints[static_cast<std::size_t>(j)];
    if (std::max(0, joint.home_sequence) != next) continue;
    if (joint.home_search_vel != 0 || joint.home_latch_vel != 0) {
      char text[120];
      std::snprintf(text, sizeof text,
                    "joint %d: switch homing needs a home switch input, which driver '%s' lacks", j,
                    joint.driver.c_str());
      latch_fault(text);
      return;
    }
    // Immediate homing: the current position becomes HOME_OFFSET, then the joint moves to HOME.
    auto& h = homing_[static_cast<std::size_t>(j)];
    joint_cmd_[static_cast<std::size_t>(j)] = joint.home_offset;
    h.active = true;
    h.start = joint.home_offset;
    h.target = joint.home;
    h.traveled = 0;
    h.velocity = 0;
    h.max_velocity = joint.home_final_vel > 0 ? std::min(joint.home_final_vel, joint.max_velocity)
                                              : joint.max_velocity;
    h.max_acceleration = joint.max_acceleration;
  }
  status_.motion = MotionState::homing;
}

void ServoLoop::advance_homing(double dt) noexcept {
  bool sequence_done = true;
  for (int j = 0; j < joint_count_; ++j) {
    auto& h = homing_[static_cast<std::size_t>(j)];
    if (!h.active) continue;
    double& pos = joint_cmd_[static_cast<std::size_t>(j)];
    double time = dt;
    const double length = std::abs(h.target - h.start);
    if (advance_profile(h.traveled, h.velocity, length, h.max_velocity, h.max_acceleration, time)) {
      pos = h.target;
      h = JointMotion{};
      status_.homed[static_cast<std::size_t>(j)] = true;
      home_pending_ &= ~(1u << j);
    } else {
      pos = h.start + (h.target > h.start ? h.traveled : -h.traveled);
      sequence_done = false;
    }
  }
  // Axes follow their joints while homing (trivkins: first joint of an axis leads).
  sync_axes_from_joints();
  if (sequence_done) {
    if (home_pending_ != 0) {
      start_home_sequence();
    } else {
      home_sequence_ = -1;
      status_.motion = MotionState::idle;
    }
  }
}

void ServoLoop::sync_axes_from_joints() noexcept {
  std::array<bool, kAxes> seen{};
  for (int j = 0; j < joint_count_; ++j) {
    const int axis = joint_axis_[static_cast<std::size_t>(j)];
    if (axis < 0 || seen[static_cast<std::size_t>(axis)]) continue;
    seen[static_cast<std::size_t>(axis)] = true;
    axis_pose_[static_cast<std::size_t>(axis)] = joint_cmd_[static_cast<std::size_t>(j)];
  }
}

void ServoLoop::advance_path(double dt) noexcept {
  const bool holding = pause_requested_ || abort_requested_;
  // A period may finish one move and go on with the next: the profile's leftover time is
  // spent on the following segment, so short moves are not slowed to one a period.
  while (dt > 0) {
    if (!has_active_) {
      if (abort_requested_ || !segments_.pop(active_)) break;
      has_active_ = true;
      path_s_ = 0;
      path_v_ = 0;
      dwell_elapsed_s_ = 0;
    }
    status_.line = active_.line;
    bool done;
    if (active_.kind == Segment::Kind::dwell) {
      if (abort_requested_) {
        done = true;
      } else if (pause_requested_) {
        done = false;
        dt = 0;
      } else {
        const double left = active_.dwell_s - dwell_elapsed_s_;
        done = left <= dt + 1e-12;
        dwell_elapsed_s_ += done ? left : dt;
        dt = done ? std::max(0.0, dt - left) : 0;
      }
    } else {
      done = advance_profile(path_s_, path_v_, active_.length, holding ? 0.0 : active_.max_velocity,
                             active_.max_acceleration, dt);
      axis_pose_ = done ? active_.end : active_.point_at(path_s_);
    }
    if (!done) break;
    has_active_ = false;
    path_v_ = 0;
    ++status_.segments_done;
  }
  status_.velocity = path_v_;
  if (abort_requested_ && path_v_ == 0) {
    flush_queue();
    status_.motion = MotionState::idle;
    return;
  }
  if (!has_active_ && segments_.size() == 0) {
    status_.motion = MotionState::idle;
  } else if (pause_requested_) {
    status_.motion = path_v_ == 0 ? MotionState::paused : MotionState::pausing;
  } else {
    status_.motion = abort_requested_ ? MotionState::stopping : MotionState::moving;
  }
}

void ServoLoop::cycle(std::int64_t wake_error_ns) noexcept {
  histogram_.add(wake_error_ns);
  ++status_.rt.cycles;
  if (wake_error_ns > config_.servo_period_ns) ++status_.rt.overruns;
  if ((status_.rt.cycles & 1023) == 1) {
    status_.rt.wake_error_p50_ns = histogram_.quantile_ns(0.5);
    status_.rt.wake_error_p99_ns = histogram_.quantile_ns(0.99);
    status_.rt.wake_error_p999_ns = histogram_.quantile_ns(0.999);
  }
  status_.rt.wake_error_max_ns = histogram_.max_ns();

  Command command;
  while (commands_.pop(command))
    apply(command);

  // Feedback and inputs.
  drivers::MachineInputs inputs;
  for (auto& binding : drivers_) {
    drivers::JointFeedback block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    binding.driver->read(block, n);
    binding.driver->read_inputs(inputs);
    for (int k = 0; k < n; ++k)
      feedback_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])] = block[k];
  }
  if (inputs.estop && status_.machine != MachineState::estop) {
    stop_now(MachineState::estop, nullptr);
    latch_fault("estop input asserted");
  }
  const bool on = status_.machine == MachineState::on;
  for (int j = 0; j < joint_count_ && on; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& fb = feedback_[k];
    char text[120];
    if (fb.fault || fb.stale) {
      status_.joint_fault[k] = true;
      std::snprintf(text, sizeof text, "joint %d: %s", j,
                    fb.fault ? "drive fault" : "feedback is stale");
      latch_fault(text);
      break;
    }
    // A tripped limit switch stops everything, except while homing a joint configured to
    // ignore its limits (its home switch shares the limit input).
    const bool ignore_limits = homing_[k].active && config_.joints[k].home_ignore_limits;
    if ((fb.min_limit || fb.max_limit) && !ignore_limits) {
      status_.joint_fault[k] = true;
      std::snprintf(text, sizeof text, "joint %d: %s limit switch tripped", j,
                    fb.min_limit ? "minimum" : "maximum");
      latch_fault(text);
      break;
    }
    const auto& joint = config_.joints[k];
    const double speed = std::abs(commands_out_[k].velocity);
    const double limit =
        joint.min_ferror + (joint.ferror - joint.min_ferror) *
                               std::min(1.0, speed / std::max(joint.max_velocity, 1e-9));
    const double error = std::abs(last_written_[k] - fb.position);
    if (error > limit) {
      status_.joint_fault[k] = true;
      std::snprintf(text, sizeof text, "joint %d: following error %.4f exceeds %.4f", j, error,
                    limit);
      latch_fault(text);
      break;
    }
  }

  if (status_.machine == MachineState::on) {
    if (home_pending_ != 0 || home_sequence_ >= 0) {
      advance_homing(period_s_);
    } else {
      advance_path(period_s_);
      for (int j = 0; j < joint_count_; ++j) {
        joint_cmd_[static_cast<std::size_t>(j)] =
            axis_pose_[static_cast<std::size_t>(joint_axis_[static_cast<std::size_t>(j)])];
      }
    }
  } else {
    // Drives off: the command follows the machine wherever it is pushed.
    for (int j = 0; j < joint_count_; ++j)
      joint_cmd_[static_cast<std::size_t>(j)] = feedback_[static_cast<std::size_t>(j)].position;
    sync_axes_from_joints();
  }

  // Commands out.
  const bool enable = status_.machine == MachineState::on;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    commands_out_[k].velocity = (joint_cmd_[k] - last_written_[k]) / period_s_;
    commands_out_[k].position = joint_cmd_[k];
    commands_out_[k].enable = enable;
    last_written_[k] = joint_cmd_[k];
  }
  for (auto& binding : drivers_) {
    drivers::JointCommand block[kJoints];
    const int n = static_cast<int>(binding.joints.size());
    for (int k = 0; k < n; ++k)
      block[k] =
          commands_out_[static_cast<std::size_t>(binding.joints[static_cast<std::size_t>(k)])];
    binding.driver->write(block, n);
  }
  publish();
}

void ServoLoop::publish() noexcept {
  status_.sequence = status_.rt.cycles;
  status_.commanded = axis_pose_;
  status_.queued = static_cast<std::uint32_t>(segments_.size() + (has_active_ ? 1 : 0));
  std::array<bool, kAxes> seen{};
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    status_.joint_commanded[k] = joint_cmd_[k];
    status_.joint_actual[k] = feedback_[k].position;
    const int axis = joint_axis_[k];
    if (axis >= 0 && !seen[static_cast<std::size_t>(axis)]) {
      seen[static_cast<std::size_t>(axis)] = true;
      status_.actual[static_cast<std::size_t>(axis)] = feedback_[k].position;
    }
  }
  published_.store(status_);
}

}  // namespace cncd::motion
