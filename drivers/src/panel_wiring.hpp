// The panel's signals as the drivers walk them (not installed): which address wires each
// input, counter, analog knob and light of config::PanelConfig, and a name for recordings.
#pragma once

#include <cstdint>
#include <string>

#include "cncd/config/panel_config.hpp"

namespace cncd::drivers {

// The wiring of counter `index` (config::PanelCounter): the MPG, then the knobs' encoders.
inline const config::PanelCounterWiring& panel_counter_wiring(const config::PanelConfig& panel,
                                                              int index) {
  return index == 0 ? panel.mpg : panel.knobs[static_cast<std::size_t>(index - 1)].encoder;
}

// The analog input of knob `index` (config::PanelAnalog).
inline const config::SignalAddress& panel_analog_address(const config::PanelConfig& panel,
                                                         int index) {
  return panel.knobs[static_cast<std::size_t>(index)].analog;
}

// The INI key of counter `index` without its suffix: "MPG", "FEED_OVERRIDE", ...
const char* panel_counter_key(int index);

// A signal's name in a recording: its INI key in lower case ("cycle_start", "mpg_a").
std::string panel_signal_name(std::string key);

// Calls f(address) for every address the panel names.
template <typename F>
void for_each_panel_address(const config::PanelConfig& panel, F&& f) {
  for (const auto& a : panel.inputs)
    f(a);
  for (int c = 0; c < config::kPanelCounters; ++c) {
    const config::PanelCounterWiring& w = panel_counter_wiring(panel, c);
    f(w.a);
    f(w.b);
    f(w.counts);
  }
  for (int k = 0; k < config::kPanelAnalogs; ++k)
    f(panel_analog_address(panel, k));
  for (const auto& a : panel.lights)
    f(a);
}

// The level of a 64-bit input word with bit `index` set to `on`.
inline std::uint64_t with_bit(std::uint64_t word, int index, bool on) {
  const std::uint64_t bit = std::uint64_t{1} << index;
  return on ? word | bit : word & ~bit;
}

}  // namespace cncd::drivers
