// A simulated spindle: its speed ramps to the command at the spindle's acceleration and its
// position (revolutions, signed) follows the speed. The sim driver turns it each servo
// period; so does the plan simulation, which reads a program without any driver.
#pragma once

#include <cmath>
#include <cstdint>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

class SpindleModel {
 public:
  // At rest; `acceleration` in rpm/s (0 = at once), `period_s` the servo period.
  void reset(double acceleration, double period_s) noexcept {
    *this = SpindleModel{};
    acceleration_ = acceleration;
    period_s_ = period_s;
  }
  CNCD_RT void command(const SpindleCommand& command) noexcept { command_ = command; }
  // One period on, unless the feedback is stale (the reading then stands); fills in the
  // speed, the position and which command the reading answers.
  CNCD_RT void step(SpindleFeedback& fb, bool stale) noexcept {
    if (!stale) {
      const SpindleCommand& c = command_;
      const double target = !c.enable ? 0.0 : c.reverse ? -std::abs(c.rpm) : std::abs(c.rpm);
      // Signed speed, so a change of direction ramps through zero.
      const double step = acceleration_ * period_s_;
      const double before = rpm_;
      if (acceleration_ <= 0 || std::abs(target - rpm_) <= step) {
        rpm_ = target;
      } else {
        rpm_ += target > rpm_ ? step : -step;
      }
      revolutions_ += (before + rpm_) * 0.5 / 60.0 * period_s_;
      // This period ran with the command: its reading answers it.
      acknowledged_ = c.sequence;
    }
    fb.rpm = std::abs(rpm_);
    fb.revolutions = revolutions_;
    fb.acknowledged = acknowledged_;
  }

 private:
  double acceleration_ = 0;
  double period_s_ = 0.001;
  SpindleCommand command_{};
  double rpm_ = 0;  // signed: negative turns in reverse
  double revolutions_ = 0;
  std::uint64_t acknowledged_ = 0;  // the command of the last period simulated
};

}  // namespace cncd::drivers
