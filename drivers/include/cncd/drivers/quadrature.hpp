// Quadrature (A/B) decoding shared by the spindle encoder and the panel's encoders.
#pragma once

#include <cstdint>

namespace cncd::drivers {

// The count change from A/B state `from` to `to` (each A << 1 | B): +1 when A leads B (00 10 11
// 01), -1 the other way, 0 when nothing changed, kQuadratureJump when both lines changed at once
// (a step was missed: the direction is unknown).
inline constexpr int kQuadratureJump = 2;
inline int quadrature_step(int from, int to) noexcept {
  static constexpr int kStep[16] = {0, -1, 1, 2, 1, 0, 2, -1, -1, 2, 0, 1, 2, 1, -1, 0};
  return kStep[from * 4 + to];
}

// A panel encoder (the MPG, an override knob): a 32-bit count that wraps, 4 counts a cycle,
// and the jumps it could not count.
class QuadratureCounter {
 public:
  // RT: the A and B levels of this sample.
  void sample(bool a, bool b) noexcept {
    const int state = (a ? 2 : 0) | (b ? 1 : 0);
    if (state_ >= 0) {
      const int step = quadrature_step(state_, state);
      if (step == kQuadratureJump) {
        ++errors_;
      } else {
        count_ += static_cast<std::uint32_t>(step);
      }
    }
    state_ = state;
  }
  std::uint32_t count() const noexcept { return count_; }
  std::uint32_t errors() const noexcept { return errors_; }

 private:
  int state_ = -1;  // -1: no sample yet
  std::uint32_t count_ = 0;
  std::uint32_t errors_ = 0;
};

}  // namespace cncd::drivers
