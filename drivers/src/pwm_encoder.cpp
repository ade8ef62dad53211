#include "pwm_encoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace cncd::drivers {

void Pwmgen::setup(double base_periods_per_cycle) {
  per_cycle_ = std::max(2.0, base_periods_per_cycle);
  left_in_cycle_ = 0;
  high_left_ = 0;
  cycle_carry_ = 0;
  duty_carry_ = 0;
}

bool Pwmgen::tick(double duty) noexcept {
  duty = std::clamp(duty, 0.0, 1.0);
  if (left_in_cycle_ == 0) {
    const double length = per_cycle_ + cycle_carry_;
    left_in_cycle_ = std::max(1, static_cast<int>(std::lround(length)));
    cycle_carry_ = length - left_in_cycle_;
    // Off is off: no carried remainder lights up a stopped spindle.
    if (duty <= 0) duty_carry_ = 0;
    const double high = duty * left_in_cycle_ + duty_carry_;
    high_left_ = std::clamp(static_cast<int>(std::lround(high)), 0, left_in_cycle_);
    duty_carry_ = duty > 0 ? high - high_left_ : 0;
  }
  --left_in_cycle_;
  if (high_left_ == 0) return false;
  --high_left_;
  return true;
}

void QuadratureDecoder::setup(int counts_per_revolution) {
  *this = QuadratureDecoder{};
  per_revolution_ = std::max(1, counts_per_revolution);
}

void QuadratureDecoder::sample(bool a, bool b, bool index, std::int64_t time_ns) noexcept {
  const int state = (a ? 2 : 0) | (b ? 1 : 0);
  if (state_ >= 0) {
    // A jump of both lines counts nothing: the index pulse puts back what it lost.
    const int step = quadrature_step(state_, state);
    if (step != kQuadratureJump) count_ += step;
  }
  state_ = state;
  if (index && !index_) {
    // The first index pulse marks a position; each later one puts back counts that noise or
    // a too fast spindle lost (or added), so the count stays whole revolutions from it.
    if (!index_seen_) {
      index_seen_ = true;
      index_count_ = count_;
    } else {
      const double turns =
          static_cast<double>(count_ - index_count_) / static_cast<double>(per_revolution_);
      count_ = index_count_ + std::llround(turns) * per_revolution_;
    }
  }
  index_ = index;
  if (window_start_ns_ < 0) {
    window_start_ns_ = time_ns;
    window_count_ = count_;
  } else if (time_ns - window_start_ns_ >= kWindowNs) {
    const double seconds = static_cast<double>(time_ns - window_start_ns_) * 1e-9;
    const double turns = static_cast<double>(std::llabs(count_ - window_count_)) /
                         static_cast<double>(per_revolution_);
    rpm_ = turns / seconds * 60.0;
    window_start_ns_ = time_ns;
    window_count_ = count_;
  }
}

}  // namespace cncd::drivers
