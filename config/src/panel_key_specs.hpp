// The [PANEL] keys of config_keys.cpp's table (not installed). "JOG_L_PLUS" and "MPG_AXIS_L"
// stand for one key per axis letter; the loader refuses the letters the machine lacks.
#pragma once

#include <array>
#include <span>

#include "key_makers.hpp"

namespace cncd::config::panel_keys {

using namespace key_makers;

constexpr std::string_view kPanel = "PANEL";

constexpr KeySpec button(std::string_view key, std::string_view help) {
  return signal_key(kPanel, key, help);
}

// A detent's distance while an MPG_STEP_n switch is on; the default depends on the units.
constexpr KeySpec step_distance(std::string_view key, std::string_view help) {
  return positive_key(kPanel, key, "", "units", help);
}

// The seven keys of an override knob, NAME_OVERRIDE_*: an encoder or an analog input.
constexpr std::array<KeySpec, 7> knob_keys(std::string_view a, std::string_view b,
                                           std::string_view counts, std::string_view scale,
                                           std::string_view analog, std::string_view analog_min,
                                           std::string_view analog_max) {
  return {
      signal_key(kPanel, a, "Override knob: encoder channel A (gpio or sim), with _B"),
      signal_key(kPanel, b, "Override knob: encoder channel B (gpio or sim), with _A"),
      signal_key(kPanel, counts,
                 "Override knob: a counter that wraps (modbus hr/ir, sim, evdev REL_*); not "
                 "with _A/_B or _ANALOG"),
      positive_key(kPanel, scale, "0.01", "ratio/count",
                   "Override change per encoder count; 0.01 = 1 % a count"),
      signal_key(kPanel, analog,
                 "Override knob: an analog input (modbus hr/ir, sim, evdev ABS_*) mapped from "
                 "_ANALOG_MIN .. _ANALOG_MAX onto the override's range; not with an encoder"),
      real_key(kPanel, analog_min, "0", -kInf, kInf, "",
               "Analog value of the lowest override (below: the lowest)"),
      real_key(kPanel, analog_max, "10", -kInf, kInf, "",
               "Analog value of the highest override (above: the highest)"),
  };
}

constexpr std::array kGeneral{
    integer_key(kPanel, "DEBOUNCE_MS", "10", 0, 1000, "ms",
                "A panel input's new level counts once it has held this long"),
    choice_key(kPanel, "DOOR_MODE", "hold", "hold|estop",
               "An open DOOR holds the program (feed hold, then spindle stop at rest, coolant "
               "off) or trips the estop"),
    button("CYCLE_START",
           "Button: runs the open program (auto, idle), resumes a paused one, one block with "
           "SINGLE_BLOCK on"),
    button("FEED_HOLD", "Button: pauses the program within the deceleration (program.pause)"),
    button("STOP", "Button: aborts the program under control (program.abort), no estop"),
    button("SINGLE_BLOCK", "Switch: on, cycle start runs one block and pauses"),
    button("OPTIONAL_STOP", "Switch: M1 stops only while it is on; unwired, M1 always stops"),
    button("BLOCK_DELETE", "Switch: '/' lines are skipped while it is on"),
    button("DOOR", "Switch: on while the door is open (interlock, see DOOR_MODE)"),
    button("MACHINE_ON", "Button: turns the machine on, as machine.on"),
    button("RESET", "Button: leaves estop, as machine.reset"),
    button("MPG_ENABLE", "Switch: the MPG jogs only while it is on; unwired, always"),
    button("MPG_STEP_1", "Switch: the MPG moves MPG_STEP_1_DISTANCE a detent"),
    button("MPG_STEP_10", "Switch: the MPG moves MPG_STEP_10_DISTANCE a detent"),
    button("MPG_STEP_100", "Switch: the MPG moves MPG_STEP_100_DISTANCE a detent"),
    button("JOG_L_PLUS",
           "Button: jogs axis L (a letter of [TRAJ] COORDINATES) in + at its default jog "
           "speed while held"),
    button("JOG_L_MINUS", "Button: jogs axis L in - while held"),
    button("MPG_AXIS_L", "Switch: the MPG moves axis L while it (and no other) is on"),
    signal_key(kPanel, "MPG_A", "MPG encoder channel A (gpio or sim), with MPG_B"),
    signal_key(kPanel, "MPG_B", "MPG encoder channel B (gpio or sim), with MPG_A"),
    signal_key(kPanel, "MPG_COUNTS",
               "MPG as a counter that wraps (modbus hr/ir, sim, evdev REL_*); not with "
               "MPG_A/MPG_B"),
    integer_key(kPanel, "MPG_COUNTS_PER_DETENT", "4", 1, 10000, "counts",
                "MPG counts of one detent (one step of the wheel)"),
    step_distance("MPG_STEP_1_DISTANCE",
                  "Distance of a detent with MPG_STEP_1 (or no step input) on; default 0.001 mm, "
                  "0.0001 in"),
    step_distance("MPG_STEP_10_DISTANCE",
                  "Distance of a detent with MPG_STEP_10 on; default 0.01 mm, 0.001 in"),
    step_distance("MPG_STEP_100_DISTANCE",
                  "Distance of a detent with MPG_STEP_100 on; default 0.1 mm, 0.01 in"),
    choice_key(kPanel, "MPG_MODE", "position", "position|velocity",
               "position: every detent moves its distance exactly; velocity: the wheel's speed "
               "is the jog speed, and the axis stops when the wheel does"),
    choice_key(kPanel, "MPG_OVERRIDE", "none", "none|feed",
               "feed: while a program runs the MPG turns the feed override"),
    signal_key(kPanel, "LIGHT_RED", "Light: estop or a fault (gpio, modbus coil, sim)"),
    signal_key(kPanel, "LIGHT_AMBER", "Light: paused, or a program waits"),
    signal_key(kPanel, "LIGHT_GREEN", "Light: a program runs"),
    signal_key(kPanel, "LAMP_CYCLE_START", "Lamp of the cycle start button: a program runs"),
    signal_key(kPanel, "LAMP_FEED_HOLD", "Lamp of the feed hold button: paused"),
};

constexpr auto kFeed =
    knob_keys("FEED_OVERRIDE_A", "FEED_OVERRIDE_B", "FEED_OVERRIDE_COUNTS", "FEED_OVERRIDE_SCALE",
              "FEED_OVERRIDE_ANALOG", "FEED_OVERRIDE_ANALOG_MIN", "FEED_OVERRIDE_ANALOG_MAX");
constexpr auto kRapid = knob_keys("RAPID_OVERRIDE_A", "RAPID_OVERRIDE_B", "RAPID_OVERRIDE_COUNTS",
                                  "RAPID_OVERRIDE_SCALE", "RAPID_OVERRIDE_ANALOG",
                                  "RAPID_OVERRIDE_ANALOG_MIN", "RAPID_OVERRIDE_ANALOG_MAX");
constexpr auto kSpindle = knob_keys(
    "SPINDLE_OVERRIDE_A", "SPINDLE_OVERRIDE_B", "SPINDLE_OVERRIDE_COUNTS", "SPINDLE_OVERRIDE_SCALE",
    "SPINDLE_OVERRIDE_ANALOG", "SPINDLE_OVERRIDE_ANALOG_MIN", "SPINDLE_OVERRIDE_ANALOG_MAX");

// The table's entries before these, then every [PANEL] key.
template <std::size_t N>
constexpr auto with_panel_keys(const std::array<KeySpec, N>& before) {
  constexpr std::size_t kAdded = kGeneral.size() + kFeed.size() + kRapid.size() + kSpindle.size();
  std::array<KeySpec, N + kAdded> all{};
  std::size_t at = 0;
  for (const auto& part : {std::span<const KeySpec>(before), std::span<const KeySpec>(kGeneral),
                           std::span<const KeySpec>(kFeed), std::span<const KeySpec>(kRapid),
                           std::span<const KeySpec>(kSpindle)}) {
    for (const KeySpec& spec : part)
      all[at++] = spec;
  }
  return all;
}

}  // namespace cncd::config::panel_keys
