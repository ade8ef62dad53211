// The panel unit on its own: debouncing, presses, counters unwrapped, the MPG's selectors.
#include <gtest/gtest.h>

#include "cncd/motion/panel.hpp"
#include "panel_fixture.hpp"

namespace cncd::test::panel {
namespace {

using motion::Panel;
using motion::PanelStatus;

constexpr auto kCycleStart = static_cast<std::size_t>(PanelInput::cycle_start);
constexpr std::uint32_t kXyz = 0b111;

struct Unit {
  explicit Unit(int debounce_ms)
      : config(panel_mill(PanelConfig::MpgMode::position, 4, debounce_ms).panel),
        panel(config, 0.001, kXyz) {}
  void period(std::uint64_t inputs, int n = 1) {
    in.inputs = inputs;
    for (int i = 0; i < n; ++i)
      panel.update(in, out);
  }
  PanelConfig config;
  Panel panel;
  drivers::PanelFeedback in;
  PanelStatus out;
};

TEST(PanelUnit, ABounceShorterThanTheDebounceIsNoPress) {
  Unit u(10);
  EXPECT_EQ(u.panel.debounce_periods(), 10);
  u.period(bit(PanelInput::cycle_start), 9);  // 9 ms: one short of DEBOUNCE_MS
  u.period(0, 3);
  EXPECT_EQ(u.out.presses[kCycleStart], 0u);
  EXPECT_EQ(u.out.inputs, 0u);
  u.period(bit(PanelInput::cycle_start), 9);
  EXPECT_EQ(u.out.inputs, 0u);
  u.period(bit(PanelInput::cycle_start));  // the 10th period it holds
  EXPECT_EQ(u.out.inputs, bit(PanelInput::cycle_start));
  EXPECT_EQ(u.out.presses[kCycleStart], 1u);
  // A drop-out shorter than the debounce while held is no release (and no second press).
  u.period(0, 5);
  u.period(bit(PanelInput::cycle_start), 20);
  EXPECT_EQ(u.out.presses[kCycleStart], 1u);
}

TEST(PanelUnit, PressesAreCountedOnDebouncedRisingEdges) {
  Unit u(10);
  for (int press = 0; press < 5; ++press) {
    u.period(bit(PanelInput::cycle_start) | bit(PanelInput::feed_hold), 12);
    u.period(bit(PanelInput::feed_hold), 12);  // feed hold held throughout: one press
  }
  EXPECT_EQ(u.out.presses[kCycleStart], 5u);
  EXPECT_EQ(u.out.presses[static_cast<std::size_t>(PanelInput::feed_hold)], 1u);
}

TEST(PanelUnit, NoDebounceCountsAtOnceAndUnwiredInputsStayOff) {
  Unit u(0);
  u.config.inputs[static_cast<std::size_t>(PanelInput::reset)] = {};
  Panel panel(u.config, 0.001, kXyz);
  u.in.inputs = bit(PanelInput::stop) | bit(PanelInput::reset);
  panel.update(u.in, u.out);
  EXPECT_EQ(u.out.inputs, bit(PanelInput::stop));
  EXPECT_EQ(u.out.presses[static_cast<std::size_t>(PanelInput::stop)], 1u);
}

TEST(PanelUnit, CountersUnwrapBySixteenAndThirtyTwoBits) {
  Unit u(0);
  u.in.counter_bits = {16, 32, 0, 16};
  u.in.counts = {65530, 0xFFFFFFF0u, 77, 3};  // first readings: the origin
  u.period(0);
  EXPECT_EQ(u.out.counts, (std::array<std::int64_t, 4>{0, 0, 0, 0}));
  u.in.counts = {5, 0x10u, 99, 65535};  // +11 across the wrap, +32, not owned, -4
  u.period(0);
  EXPECT_EQ(u.out.counts, (std::array<std::int64_t, 4>{11, 32, 0, -4}));
  u.in.counts = {65534, 0xFFFFFFFEu, 99, 65535};  // -7 back across the wrap, -18
  u.period(0);
  EXPECT_EQ(u.out.counts, (std::array<std::int64_t, 4>{4, 14, 0, -4}));
  // Round and round the 16-bit register in steps under half its span: every count kept.
  std::uint32_t raw = 65534;
  for (int i = 0; i < 100; ++i) {
    raw = (raw + 30000) & 0xFFFF;
    u.in.counts[0] = raw;
    u.period(0);
  }
  EXPECT_EQ(u.out.counts[0], 4 + 100 * 30000);
  u.in.analog = {1.5, 2.5, 10};
  u.period(0);
  EXPECT_EQ(u.out.analog, (std::array<double, 3>{1.5, 2.5, 10}));
}

TEST(PanelUnit, TheMpgSelectsOneAxisAndTheHighestStep) {
  Unit u(0);
  u.period(mpg_axis_bit(1));
  EXPECT_EQ(u.out.mpg_axis, 1);
  EXPECT_DOUBLE_EQ(u.out.mpg_step, 0.001);  // none on: STEP_1's distance
  u.period(mpg_axis_bit(1) | mpg_axis_bit(2) | bit(PanelInput::mpg_step_10));
  EXPECT_EQ(u.out.mpg_axis, -1);  // two at once: none
  EXPECT_DOUBLE_EQ(u.out.mpg_step, 0.01);
  u.period(mpg_axis_bit(5) | bit(PanelInput::mpg_step_10) | bit(PanelInput::mpg_step_100));
  EXPECT_EQ(u.out.mpg_axis, -1);  // C: the machine has no such axis
  EXPECT_DOUBLE_EQ(u.out.mpg_step, 0.1);
  EXPECT_FALSE(u.panel.mpg_enabled());  // MPG_ENABLE wired and off
  u.period(bit(PanelInput::mpg_enable));
  EXPECT_TRUE(u.panel.mpg_enabled());

  // No selector wired: no axis, whatever the inputs say; no MPG_ENABLE wired: enabled.
  PanelConfig bare = u.config;
  for (int axis = 0; axis < config::kPanelAxes; ++axis)
    bare.inputs[static_cast<std::size_t>(PanelInput::mpg_axis_x) + static_cast<std::size_t>(axis)] =
        {};
  bare.inputs[static_cast<std::size_t>(PanelInput::mpg_enable)] = {};
  Panel panel(bare, 0.001, kXyz);
  PanelStatus out;
  u.in.inputs = mpg_axis_bit(0);
  panel.update(u.in, out);
  EXPECT_EQ(out.mpg_axis, -1);
  EXPECT_TRUE(panel.mpg_enabled());
}

}  // namespace
}  // namespace cncd::test::panel
