#include "stepgen.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::drivers {

int ticks_for(std::int64_t ns, std::int64_t base_period_ns) {
  if (base_period_ns <= 0) return 1;
  const std::int64_t ticks = (ns + base_period_ns - 1) / base_period_ns;
  return static_cast<int>(std::max<std::int64_t>(1, ticks));
}

void Stepgen::setup(const StepgenTiming& timing) {
  timing_ = timing;
  // A full step cycle needs STEPLEN + STEPSPACE base periods; faster commands could only be
  // followed by dropping steps.
  const double timing_limit =
      1.0 / (timing.base_period_s * (timing.steplen_ticks + timing.stepspace_ticks));
  max_velocity_ = timing.max_velocity_steps > 0 ? std::min(timing.max_velocity_steps, timing_limit)
                                                : timing_limit;
}

void Stepgen::prime(std::int64_t steps) noexcept {
  count_ = steps;
  position_ = static_cast<double>(steps);
  velocity_ = 0;
}

void Stepgen::follow(double target_steps, double velocity_steps, double since_command_s) noexcept {
  const double dt = timing_.base_period_s;
  const double servo = timing_.servo_period_s;
  // The command is where the joint should be one servo period after it arrived; in between,
  // the target moves along with the feed-forward velocity.
  const double ahead = std::max(0.0, servo - since_command_s);
  const double error = target_steps - velocity_steps * ahead - position_;
  double correction = error / servo;
  const double accel = timing_.max_acceleration_steps;
  if (accel > 0) {
    const double braking = std::sqrt(2.0 * accel * std::abs(error));
    correction = std::clamp(correction, -braking, braking);
  }
  double wanted = std::clamp(velocity_steps + correction, -max_velocity_, max_velocity_);
  if (accel > 0) wanted = std::clamp(wanted, velocity_ - accel * dt, velocity_ + accel * dt);
  velocity_ = wanted;
  position_ += velocity_ * dt;
}

void Stepgen::tick(double target_steps, double velocity_steps, double since_command_s,
                   bool enable) noexcept {
  if (high_left_ > 0) {
    if (--high_left_ == 0) {
      step_ = false;
      space_left_ = timing_.stepspace_ticks;
      hold_left_ = timing_.dirhold_ticks;
    }
  } else {
    if (space_left_ > 0) --space_left_;
    if (hold_left_ > 0) --hold_left_;
    if (setup_left_ > 0) --setup_left_;
  }
  if (!enable) {
    // Drives off: nothing moves, and the smooth position stays where the motor is.
    position_ = static_cast<double>(count_);
    velocity_ = 0;
    return;
  }
  follow(target_steps, velocity_steps, since_command_s);
  if (step_) return;
  const double behind = position_ - static_cast<double>(count_);
  const int wanted = behind > 0.5 ? 1 : (behind < -0.5 ? -1 : 0);
  if (wanted == 0) return;
  if (wanted != direction_) {
    if (hold_left_ == 0) {
      direction_ = wanted;
      setup_left_ = timing_.dirsetup_ticks;
    }
    return;
  }
  if (space_left_ == 0 && setup_left_ == 0) {
    step_ = true;
    high_left_ = timing_.steplen_ticks;
    count_ += direction_;
  }
}

}  // namespace cncd::drivers
