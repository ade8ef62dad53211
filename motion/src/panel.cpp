#include "cncd/motion/panel.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace cncd::motion {
namespace {

using config::PanelInput;

constexpr std::uint64_t bit(PanelInput input) noexcept {
  return std::uint64_t{1} << static_cast<int>(input);
}

constexpr std::uint64_t bit(int input) noexcept {
  return std::uint64_t{1} << input;
}

// The signed change from `last` to `now` of a counter `bits` wide: a wrap in either direction
// reads as the short way round.
std::int64_t wrapped_delta(std::uint32_t now, std::uint32_t last, int bits) noexcept {
  if (bits >= 32) return static_cast<std::int32_t>(now - last);
  const std::uint32_t mask = (std::uint32_t{1} << bits) - 1;
  const std::uint32_t diff = (now - last) & mask;
  const std::uint32_t sign = std::uint32_t{1} << (bits - 1);
  return (diff & sign) != 0 ? static_cast<std::int64_t>(diff) - (std::int64_t{1} << bits)
                            : static_cast<std::int64_t>(diff);
}

}  // namespace

Panel::Panel(const config::PanelConfig& config, double period_s, std::uint32_t axes_present)
    : config_(config) {
  // A level must hold the whole of DEBOUNCE_MS, so a part-period rounds up.
  const double periods = config.debounce_ms * 1e-3 / period_s;
  debounce_periods_ = static_cast<int>(std::ceil(periods - 1e-9));
  debounce_periods_ = std::clamp(debounce_periods_, 0, 65535);
  for (int i = 0; i < config::kPanelInputs; ++i) {
    if (config.inputs[static_cast<std::size_t>(i)].given()) wired_ |= bit(i);
  }
  for (int axis = 0; axis < config::kPanelAxes; ++axis) {
    const int input = static_cast<int>(PanelInput::mpg_axis_x) + axis;
    if ((wired_ & bit(input)) != 0 && (axes_present & (1u << axis)) != 0)
      axis_inputs_ |= bit(input);
  }
}

void Panel::update(const drivers::PanelFeedback& in, PanelStatus& out) noexcept {
  debounce(in.inputs & wired_, out);
  unwrap(in, out);
  out.analog = in.analog;
  select_mpg(out);
}

void Panel::debounce(std::uint64_t raw, PanelStatus& out) noexcept {
  const std::uint64_t differs = raw ^ level_;
  std::uint64_t rising = 0;
  for (std::uint64_t all = wired_; all != 0; all &= all - 1) {
    const int i = std::countr_zero(all);
    auto& held = held_[static_cast<std::size_t>(i)];
    if ((differs & bit(i)) == 0) {
      held = 0;
      continue;
    }
    if (++held < debounce_periods_) continue;
    held = 0;
    level_ ^= bit(i);
    if ((level_ & bit(i)) != 0) rising |= bit(i);
  }
  for (; rising != 0; rising &= rising - 1)
    ++out.presses[static_cast<std::size_t>(std::countr_zero(rising))];
  out.inputs = level_;
}

void Panel::unwrap(const drivers::PanelFeedback& in, PanelStatus& out) noexcept {
  for (std::size_t c = 0; c < static_cast<std::size_t>(config::kPanelCounters); ++c) {
    const int bits = in.counter_bits[c];
    if (bits <= 0) continue;  // no driver owns it this period
    const std::uint32_t raw = in.counts[c];
    if (seen_[c]) out.counts[c] += wrapped_delta(raw, last_raw_[c], std::min(bits, 32));
    seen_[c] = true;
    last_raw_[c] = raw;
  }
}

void Panel::select_mpg(PanelStatus& out) noexcept {
  const std::uint64_t axes = level_ & axis_inputs_;
  out.mpg_axis = std::popcount(axes) == 1
                     ? static_cast<std::int8_t>(std::countr_zero(axes) -
                                                static_cast<int>(PanelInput::mpg_axis_x))
                     : std::int8_t{-1};
  int step = 0;
  if ((level_ & bit(PanelInput::mpg_step_100)) != 0) {
    step = 2;
  } else if ((level_ & bit(PanelInput::mpg_step_10)) != 0) {
    step = 1;
  }
  out.mpg_step = config_.mpg_step_distance[static_cast<std::size_t>(step)];
  mpg_enabled_ =
      (wired_ & bit(PanelInput::mpg_enable)) == 0 || (level_ & bit(PanelInput::mpg_enable)) != 0;
}

}  // namespace cncd::motion
