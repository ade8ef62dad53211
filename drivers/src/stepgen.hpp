// Software step generation for one joint, advanced once per base period (not installed).
// A velocity- and acceleration-limited position follows the servo command (interpolated with
// its feed-forward velocity); a step is emitted whenever that position is more than half a
// step from the step count and STEPLEN / STEPSPACE / DIRSETUP / DIRHOLD allow it.
#pragma once

#include <cstdint>

namespace cncd::drivers {

struct StepgenTiming {
  double base_period_s = 25e-6;
  double servo_period_s = 1e-3;
  int steplen_ticks = 1;  // base periods the step line stays high
  int stepspace_ticks = 1;
  int dirsetup_ticks = 1;             // between a direction change and the next step
  int dirhold_ticks = 1;              // between the end of a step and a direction change
  double max_velocity_steps = 0;      // steps/s; the timing limit is applied on top
  double max_acceleration_steps = 0;  // steps/s^2; 0 = unlimited
};

// Base periods covering `ns`, at least one.
int ticks_for(std::int64_t ns, std::int64_t base_period_ns);

class Stepgen {
 public:
  void setup(const StepgenTiming& timing);
  // RT, base thread: places the step count at `steps` without stepping (first command, or a
  // position the machine restarts at).
  void prime(std::int64_t steps) noexcept;
  // RT, base thread: one base period. `target_steps` and `velocity_steps` (steps/s) are the
  // servo's latest command, `since_command_s` the time since it arrived.
  void tick(double target_steps, double velocity_steps, double since_command_s,
            bool enable) noexcept;

  bool step_line() const noexcept { return step_; }
  bool dir_line() const noexcept { return direction_ < 0; }  // high = negative direction
  std::int64_t count() const noexcept { return count_; }

 private:
  void follow(double target_steps, double velocity_steps, double since_command_s) noexcept;

  StepgenTiming timing_;
  double max_velocity_ = 0;
  double position_ = 0;  // steps, the smooth position the count follows
  double velocity_ = 0;  // steps/s
  std::int64_t count_ = 0;
  int direction_ = 1;
  bool step_ = false;
  int high_left_ = 0;
  int space_left_ = 0;
  int hold_left_ = 0;
  int setup_left_ = 0;
};

}  // namespace cncd::drivers
