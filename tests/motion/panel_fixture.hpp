// A machine with a panel ([PANEL]) built by hand, and a driver that reports the panel's inputs
// a test sets and keeps the lights it is told: what the panel tests drive in virtual time.
#pragma once

#include <cstdint>

#include "machine_fixture.hpp"

namespace cncd::test::panel {

using config::PanelConfig;
using config::PanelInput;

constexpr std::uint64_t bit(PanelInput input) {
  return std::uint64_t{1} << static_cast<int>(input);
}
constexpr std::uint64_t mpg_axis_bit(int axis) {
  return std::uint64_t{1} << (static_cast<int>(PanelInput::mpg_axis_x) + axis);
}

// Reports PanelFeedback as the test sets it: the MPG a 32-bit counter (16 when told).
class PanelDrive final : public FakeDriver {
 public:
  PanelDrive() : FakeDriver("panel") {}
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    feedback.panel.inputs = inputs;
    feedback.panel.counts = counts;
    feedback.panel.counter_bits = bits;
    feedback.panel.analog = analog;
  }
  void write_io(const drivers::IoCommand& command) noexcept override { lights = command.panel; }
  void turn(std::int64_t counts_more) {
    counts[0] = static_cast<std::uint32_t>(static_cast<std::int64_t>(counts[0]) + counts_more);
  }
  std::uint64_t inputs = 0;
  std::array<std::uint32_t, config::kPanelCounters> counts{};
  std::array<std::uint8_t, config::kPanelCounters> bits{32, 32, 32, 32};
  std::array<double, config::kPanelAnalogs> analog{};
  std::uint32_t lights = 0;
};

// An address no driver of the test machine owns (PanelDrive stands in for it).
inline config::SignalAddress wired(const char* code) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::evdev;
  a.device = "/dev/input/test";
  a.code = code;
  a.text = std::string("evdev:/dev/input/test:") + code;
  return a;
}

// small_mill() with every panel input wired, the MPG a counter.
inline config::MachineConfig panel_mill(PanelConfig::MpgMode mode, int counts_per_detent,
                                        int debounce_ms = 0) {
  config::MachineConfig c = small_mill();
  PanelConfig& p = c.panel;
  p.present = true;
  p.debounce_ms = debounce_ms;
  for (int i = 0; i < config::kPanelInputs; ++i) {
    const int axis = (i - static_cast<int>(PanelInput::jog_plus_x)) % config::kPanelAxes;
    // Jog buttons and axis selectors only for the machine's axes.
    if (i >= static_cast<int>(PanelInput::jog_plus_x) &&
        !c.axes[static_cast<std::size_t>(axis)].present)
      continue;
    p.inputs[static_cast<std::size_t>(i)] = wired("KEY_A");
  }
  p.mpg.counts = wired("REL_DIAL");
  for (auto& knob : p.knobs) {
    knob.encoder.counts = wired("REL_WHEEL");
    knob.analog = wired("ABS_X");
  }
  p.mpg_counts_per_detent = counts_per_detent;
  p.mpg_mode = mode;
  return c;
}

struct PanelRig {
  explicit PanelRig(const config::MachineConfig& c) : config(c), m(config, kCaps, nullptr, &drive) {
    m.ready();
  }
  static constexpr std::uint32_t kCaps =
      drivers::kCapHomeSwitch | drivers::kCapLimitSwitches | drivers::kCapEstopInput;
  // MPG on `axis`, enabled, with step `step` (0, 1, 2: STEP_1, _10, _100).
  void select(int axis, int step) {
    drive.inputs = mpg_axis_bit(axis) | bit(PanelInput::mpg_enable);
    if (step == 1) drive.inputs |= bit(PanelInput::mpg_step_10);
    if (step == 2) drive.inputs |= bit(PanelInput::mpg_step_100);
    m.cycles(1 + config.panel.debounce_ms);
  }
  config::MachineConfig config;
  PanelDrive drive;
  VirtualMachine m;
};

}  // namespace cncd::test::panel
