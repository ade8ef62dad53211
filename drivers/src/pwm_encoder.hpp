// Spindle signals the base thread makes and decodes (not installed): a PWM generator whose
// average duty is exact although each period's high time is whole base periods, and a
// quadrature encoder decoder.
#pragma once

#include <cstdint>

#include "cncd/drivers/quadrature.hpp"

namespace cncd::drivers {

class Pwmgen {
 public:
  // Non-RT. `base_periods_per_cycle` = base rate / PWM frequency, at least 2.
  void setup(double base_periods_per_cycle);
  // RT, base thread: the line level for this base period at `duty` (0 .. 1). A cycle's high
  // time is rounded to whole base periods, and the rounding error is carried into the next
  // cycle (error diffusion), so the mean duty over many cycles is `duty` exactly; the same is
  // done for the cycle length when the base rate is no multiple of the PWM frequency.
  bool tick(double duty) noexcept;

 private:
  double per_cycle_ = 2;
  int left_in_cycle_ = 0;
  int high_left_ = 0;
  double cycle_carry_ = 0;
  double duty_carry_ = 0;
};

class QuadratureDecoder {
 public:
  // Non-RT. `counts_per_revolution` = 4 x ENCODER_PPR.
  void setup(int counts_per_revolution);
  // RT, base thread: the A, B and index levels of this base period at `time_ns`.
  void sample(bool a, bool b, bool index, std::int64_t time_ns) noexcept;
  std::int64_t count() const noexcept { return count_; }
  double revolutions() const noexcept {
    return static_cast<double>(count_) / static_cast<double>(per_revolution_);
  }
  // Speed over the last completed measuring window, >= 0.
  double rpm() const noexcept { return rpm_; }

  static constexpr std::int64_t kWindowNs = 10'000'000;

 private:
  int per_revolution_ = 4;
  int state_ = -1;  // A << 1 | B of the previous sample, -1 = none yet
  bool index_ = false;
  bool index_seen_ = false;
  std::int64_t index_count_ = 0;  // the count at the first index pulse
  std::int64_t count_ = 0;
  std::int64_t window_start_ns_ = -1;
  std::int64_t window_count_ = 0;
  double rpm_ = 0;
};

}  // namespace cncd::drivers
