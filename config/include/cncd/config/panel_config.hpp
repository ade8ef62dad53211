// [PANEL]: the machine's own controls (docs/drivers.md, "Panel"): buttons and switches, the MPG
// handwheel, override knobs and the lamps of a stack light, each wired by a signal address.
// The enums index the arrays here, the drivers' PanelFeedback and the servo thread's
// PanelStatus, so that every part names a panel signal the same way.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "cncd/config/signal_address.hpp"

namespace cncd::config {

inline constexpr int kPanelAxes = 9;  // as kMaxAxes: one per letter of XYZABCUVW

// The panel's digital inputs. Each is a bit (1 << value) of PanelFeedback::inputs and
// PanelStatus::inputs. Buttons act on their press (a debounced rising edge); switches
// (single block, optional stop, block delete, door, MPG enable, the step and axis selectors)
// act on their level. The JOG and MPG_AXIS inputs come in axis order (kAxisLetters).
enum class PanelInput : std::uint8_t {
  cycle_start,
  feed_hold,
  stop,
  single_block,
  optional_stop,
  block_delete,
  door,  // on (1) while the door is open
  machine_on,
  reset,
  mpg_enable,
  mpg_step_1,
  mpg_step_10,
  mpg_step_100,
  jog_plus_x,                             // .. jog_plus_x + 8 for W
  jog_minus_x = jog_plus_x + kPanelAxes,  // .. + 8
  mpg_axis_x = jog_minus_x + kPanelAxes,  // .. + 8
  count = mpg_axis_x + kPanelAxes
};
inline constexpr int kPanelInputs = static_cast<int>(PanelInput::count);
static_assert(kPanelInputs <= 64);

// Counters that wrap: the MPG and the override knobs given as encoders.
enum class PanelCounter : std::uint8_t {
  mpg,
  feed_override,
  rapid_override,
  spindle_override,
  count
};
inline constexpr int kPanelCounters = static_cast<int>(PanelCounter::count);

// Analog override knobs (0-10 V on a register, a sim signal).
enum class PanelAnalog : std::uint8_t { feed_override, rapid_override, spindle_override, count };
inline constexpr int kPanelAnalogs = static_cast<int>(PanelAnalog::count);

// The panel's outputs: bit (1 << value) of the drivers' IoCommand::panel.
enum class PanelLight : std::uint8_t {
  red,    // estop or a fault
  amber,  // paused, or a program waits (tool change, M0/M1, an input)
  green,  // a program runs
  lamp_cycle_start,
  lamp_feed_hold,
  count
};
inline constexpr int kPanelLights = static_cast<int>(PanelLight::count);

// A counter: an A/B quadrature encoder (decoded by the driver: gpio in its base thread, sim
// each servo period, 4 counts a cycle) or a counter the driver reads (COUNTS: a Modbus
// register, 16 bits, or a sim signal, 32 bits), that wraps.
struct PanelCounterWiring {
  SignalAddress a;
  SignalAddress b;
  SignalAddress counts;
  bool given() const { return a.given() || counts.given(); }
};

// An override knob: an encoder (each count changes the ratio by `per_count`) or an analog
// input (`analog_min` gives the lowest ratio the INI allows, `analog_max` the highest).
struct OverrideKnob {
  PanelCounterWiring encoder;
  double per_count = 0.01;  // <NAME>_OVERRIDE_SCALE, ratio per count (0.01 = 1 %)
  SignalAddress analog;
  double analog_min = 0;  // <NAME>_OVERRIDE_ANALOG_MIN
  double analog_max = 10;
};

struct PanelConfig {
  bool present = false;  // the INI has a [PANEL] section
  int debounce_ms = 10;  // DEBOUNCE_MS: a level counts once it has held this long
  enum class DoorMode : std::uint8_t { hold, estop };
  DoorMode door_mode = DoorMode::hold;  // DOOR_MODE
  // Indexed by PanelInput: CYCLE_START, FEED_HOLD, STOP, SINGLE_BLOCK, OPTIONAL_STOP,
  // BLOCK_DELETE, DOOR, MACHINE_ON, RESET, MPG_ENABLE, MPG_STEP_1/10/100, JOG_<axis>_PLUS,
  // JOG_<axis>_MINUS, MPG_AXIS_<axis>.
  std::array<SignalAddress, kPanelInputs> inputs;
  // The MPG: MPG_A/MPG_B or MPG_COUNTS; MPG_COUNTS_PER_DETENT counts make one detent, which
  // moves the selected step's distance (machine units): MPG_STEP_1_DISTANCE .. _100_DISTANCE.
  // No step input on: the first step. No MPG_ENABLE: always enabled.
  PanelCounterWiring mpg;
  int mpg_counts_per_detent = 4;
  std::array<double, 3> mpg_step_distance{0.001, 0.01, 0.1};
  enum class MpgMode : std::uint8_t { position, velocity };
  MpgMode mpg_mode = MpgMode::position;  // MPG_MODE
  bool mpg_override_feed = false;        // MPG_OVERRIDE = feed: in auto it turns the feed override
  // FEED_OVERRIDE_*, RAPID_OVERRIDE_*, SPINDLE_OVERRIDE_* (A, B, COUNTS, SCALE, ANALOG,
  // ANALOG_MIN, ANALOG_MAX); indexed by PanelAnalog (the same order as the counters after mpg).
  std::array<OverrideKnob, kPanelAnalogs> knobs;
  // Indexed by PanelLight: LIGHT_RED, LIGHT_AMBER, LIGHT_GREEN, LAMP_CYCLE_START,
  // LAMP_FEED_HOLD.
  std::array<SignalAddress, kPanelLights> lights;

  const SignalAddress& input(PanelInput which) const {
    return inputs[static_cast<std::size_t>(which)];
  }
};

// The INI key of an input ("CYCLE_START", "JOG_X_PLUS", "MPG_AXIS_Z") and of a light.
std::string panel_input_key(PanelInput which);
std::string_view panel_light_key(PanelLight which);

}  // namespace cncd::config
