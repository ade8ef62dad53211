// The panel's inputs ([PANEL]) as the servo thread reads them each period: levels debounced,
// presses counted, counters unwrapped, the MPG's axis and step selected. Usable on its own;
// the servo loop owns one and publishes its PanelStatus.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/panel_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {

class Panel {
 public:
  // Non-RT. `config` must outlive the panel; `period_s` is the servo period. `axes_present`
  // bit i: the machine has axis i (a selector of an axis it lacks selects none).
  Panel(const config::PanelConfig& config, double period_s, std::uint32_t axes_present);

  // RT: one servo period's raw readings into `out` (every field but mpg_jogging and lights,
  // which the servo loop owns).
  CNCD_RT void update(const drivers::PanelFeedback& in, PanelStatus& out) noexcept;
  // RT. The MPG may move an axis: MPG_ENABLE on, or none wired.
  CNCD_RT bool mpg_enabled() const noexcept { return mpg_enabled_; }
  // Periods a level must hold before it counts (DEBOUNCE_MS rounded up to whole periods).
  int debounce_periods() const noexcept { return debounce_periods_; }

 private:
  CNCD_RT void debounce(std::uint64_t raw, PanelStatus& out) noexcept;
  CNCD_RT void unwrap(const drivers::PanelFeedback& in, PanelStatus& out) noexcept;
  CNCD_RT void select_mpg(PanelStatus& out) noexcept;

  const config::PanelConfig& config_;
  int debounce_periods_ = 0;
  std::uint64_t wired_ = 0;        // inputs the config gives an address
  std::uint64_t axis_inputs_ = 0;  // MPG_AXIS_* inputs wired for axes the machine has
  std::uint64_t level_ = 0;        // debounced
  std::array<std::uint16_t, config::kPanelInputs> held_{};  // periods the raw level differs
  std::array<std::uint32_t, config::kPanelCounters> last_raw_{};
  std::array<bool, config::kPanelCounters> seen_{};  // a first reading is the origin
  bool mpg_enabled_ = true;
};

}  // namespace cncd::motion
