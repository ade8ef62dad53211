#include <string>

#include "cncd/config/machine_config.hpp"

namespace cncd::config {

std::string panel_input_key(PanelInput which) {
  static constexpr std::string_view kNames[] = {
      "CYCLE_START",  "FEED_HOLD",   "STOP",        "SINGLE_BLOCK", "OPTIONAL_STOP",
      "BLOCK_DELETE", "DOOR",        "MACHINE_ON",  "RESET",        "MPG_ENABLE",
      "MPG_STEP_1",   "MPG_STEP_10", "MPG_STEP_100"};
  const int n = static_cast<int>(which);
  constexpr int kNamed = static_cast<int>(std::size(kNames));
  static_assert(kNamed == static_cast<int>(PanelInput::jog_plus_x));
  if (n < kNamed) return std::string(kNames[n]);
  const int axis = (n - kNamed) % kPanelAxes;
  const std::string letter(1, kAxisLetters[static_cast<std::size_t>(axis)]);
  if (which < PanelInput::jog_minus_x) return "JOG_" + letter + "_PLUS";
  if (which < PanelInput::mpg_axis_x) return "JOG_" + letter + "_MINUS";
  return "MPG_AXIS_" + letter;
}

std::string_view panel_light_key(PanelLight which) {
  static constexpr std::string_view kNames[] = {"LIGHT_RED", "LIGHT_AMBER", "LIGHT_GREEN",
                                                "LAMP_CYCLE_START", "LAMP_FEED_HOLD"};
  static_assert(std::size(kNames) == kPanelLights);
  return kNames[static_cast<std::size_t>(which)];
}

}  // namespace cncd::config
