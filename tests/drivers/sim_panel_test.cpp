// The panel's `sim:NAME` signals on the sim driver: buttons and switches, counters that wrap,
// A/B encoders decoded each servo period, analog knobs and the lights.
#include <cstdint>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/sim_driver.hpp"

namespace cncd::drivers {
namespace {

using config::PanelAnalog;
using config::PanelCounter;
using config::PanelInput;
using config::PanelLight;

config::SignalAddress sim(const std::string& name) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::sim;
  a.name = name;
  a.text = "sim:" + name;
  return a;
}

constexpr std::uint64_t bit(PanelInput which) {
  return std::uint64_t{1} << static_cast<int>(which);
}

config::MachineConfig machine() {
  config::MachineConfig c;
  c.servo_period_ns = 1'000'000;
  c.panel.present = true;
  return c;
}

// One servo period: the lights commanded, the panel read.
PanelFeedback period(SimDriver& sim, std::uint32_t lights = 0) {
  IoCommand command;
  command.panel = lights;
  sim.write_io(command);
  IoFeedback feedback;
  sim.read_io(feedback);
  return feedback.panel;
}

TEST(SimPanel, ButtonsAndSwitchesReportTheirSignals) {
  auto c = machine();
  c.panel.inputs[static_cast<std::size_t>(PanelInput::cycle_start)] = sim("start");
  c.panel.inputs[static_cast<std::size_t>(PanelInput::door)] = sim("door");
  c.panel.inputs[static_cast<std::size_t>(PanelInput::mpg_axis_x) + 2] = sim("axis_z");
  SimDriver sim;
  ASSERT_EQ(sim.configure(c, {}), "");
  EXPECT_EQ(period(sim).inputs, 0u);
  EXPECT_TRUE(sim.set_signal("start", 1));
  EXPECT_TRUE(sim.set_signal("axis_z", 0.5));  // any value but 0 is on
  const std::uint64_t axis_z = std::uint64_t{1} << (static_cast<int>(PanelInput::mpg_axis_x) + 2);
  EXPECT_EQ(period(sim).inputs, bit(PanelInput::cycle_start) | axis_z);
  EXPECT_TRUE(sim.set_signal("start", 0));
  EXPECT_TRUE(sim.set_signal("door", 1));
  EXPECT_EQ(period(sim).inputs, bit(PanelInput::door) | axis_z);
  EXPECT_FALSE(sim.set_signal("no_such_signal", 1));
}

// Bits of inputs no sim signal wires are the other drivers': left as they were.
TEST(SimPanel, InputsOfOtherDriversAreLeftAlone) {
  auto c = machine();
  c.panel.inputs[static_cast<std::size_t>(PanelInput::stop)] = sim("stop");
  SimDriver sim;
  ASSERT_EQ(sim.configure(c, {}), "");
  IoFeedback feedback;
  feedback.panel.inputs = bit(PanelInput::reset) | bit(PanelInput::stop);
  feedback.panel.counts[0] = 77;
  sim.read_io(feedback);
  EXPECT_EQ(feedback.panel.inputs, bit(PanelInput::reset));
  EXPECT_EQ(feedback.panel.counts[0], 77u);
  EXPECT_EQ(feedback.panel.counter_bits[0], 0);
}

TEST(SimPanel, CountersAreThirtyTwoBitIntegersThatWrap) {
  auto c = machine();
  c.panel.mpg.counts = sim("mpg");
  c.panel.knobs[1].encoder.counts = sim("rapid");
  SimDriver sim;
  ASSERT_EQ(sim.configure(c, {}), "");
  PanelFeedback p = period(sim);
  EXPECT_EQ(p.counter_bits[static_cast<std::size_t>(PanelCounter::mpg)], 32);
  EXPECT_EQ(p.counter_bits[static_cast<std::size_t>(PanelCounter::rapid_override)], 32);
  EXPECT_EQ(p.counter_bits[static_cast<std::size_t>(PanelCounter::feed_override)], 0);
  sim.set_signal("mpg", 400);
  sim.set_signal("rapid", -3);
  p = period(sim);
  EXPECT_EQ(p.counts[static_cast<std::size_t>(PanelCounter::mpg)], 400u);
  EXPECT_EQ(p.counts[static_cast<std::size_t>(PanelCounter::rapid_override)], 0xfffffffdu);
  sim.set_signal("mpg", 4294967296.0 + 5);  // one past the top wraps to 5
  sim.set_signal("rapid", 2.6);             // whole counts, rounded
  p = period(sim);
  EXPECT_EQ(p.counts[static_cast<std::size_t>(PanelCounter::mpg)], 5u);
  EXPECT_EQ(p.counts[static_cast<std::size_t>(PanelCounter::rapid_override)], 3u);
}

TEST(SimPanel, AnalogKnobsReportTheirValue) {
  auto c = machine();
  c.panel.knobs[static_cast<std::size_t>(PanelAnalog::spindle_override)].analog = sim("knob");
  SimDriver sim;
  ASSERT_EQ(sim.configure(c, {}), "");
  sim.set_signal("knob", 4.75);
  EXPECT_DOUBLE_EQ(period(sim).analog[static_cast<std::size_t>(PanelAnalog::spindle_override)],
                   4.75);
}

TEST(SimPanel, LightsWriteTheirSignals) {
  auto c = machine();
  c.panel.lights[static_cast<std::size_t>(PanelLight::red)] = sim("red");
  c.panel.lights[static_cast<std::size_t>(PanelLight::lamp_feed_hold)] = sim("hold_lamp");
  SimDriver sim;
  ASSERT_EQ(sim.configure(c, {}), "");
  EXPECT_EQ(sim.signal_value("red"), 0.0);
  period(sim, 1u << static_cast<int>(PanelLight::lamp_feed_hold));
  EXPECT_EQ(sim.signal_value("red"), 0.0);
  EXPECT_EQ(sim.signal_value("hold_lamp"), 1.0);
  period(sim, (1u << static_cast<int>(PanelLight::red)) | (1u << 3));
  EXPECT_EQ(sim.signal_value("red"), 1.0);
  EXPECT_EQ(sim.signal_value("hold_lamp"), 0.0);
}

class SimQuadrature : public ::testing::Test {
 protected:
  void SetUp() override {
    auto c = machine();
    c.panel.mpg.a = sim("mpg_a");
    c.panel.mpg.b = sim("mpg_b");
    ASSERT_EQ(sim_.configure(c, {}), "");
    period(sim_);
  }
  // Turns the wheel `counts` quadrature steps (negative: backwards), one a servo period.
  std::uint32_t turn(int counts) {
    for (int i = 0; i < std::abs(counts); ++i) {
      phase_ = (phase_ + (counts > 0 ? 1 : 3)) % 4;
      // A leads B: 00 10 11 01.
      sim_.set_signal("mpg_a", phase_ == 1 || phase_ == 2);
      sim_.set_signal("mpg_b", phase_ == 2 || phase_ == 3);
      last_ = period(sim_);
    }
    return last_.counts[0];
  }

  SimDriver sim_;
  int phase_ = 0;
  PanelFeedback last_;
};

TEST_F(SimQuadrature, FourCountsACycleInBothDirections) {
  EXPECT_EQ(turn(400), 400u);
  EXPECT_EQ(last_.counter_bits[0], 32);
  EXPECT_EQ(turn(-150), 250u);
  EXPECT_EQ(turn(-250), 0u);
  EXPECT_EQ(sim_.quadrature_errors(PanelCounter::mpg), 0u);
}

TEST_F(SimQuadrature, TheCountWrapsAtThirtyTwoBits) {
  EXPECT_EQ(turn(-1), 0xffffffffu);
  EXPECT_EQ(turn(-4), 0xfffffffbu);
  EXPECT_EQ(turn(7), 2u);
}

// A random walk, seeded: the count is the sum of the steps, whatever the order.
TEST_F(SimQuadrature, ARandomWalkIsCountedExactly) {
  std::mt19937 random(25);
  std::int64_t sum = 0;
  for (int i = 0; i < 200; ++i) {
    const int steps = static_cast<int>(random() % 41) - 20;
    sum += steps;
    turn(steps);
  }
  EXPECT_EQ(last_.counts[0], static_cast<std::uint32_t>(sum));
  EXPECT_EQ(sim_.quadrature_errors(PanelCounter::mpg), 0u);
}

TEST_F(SimQuadrature, AJumpOfBothLinesCountsNothingAndIsAnError) {
  turn(4);
  sim_.set_signal("mpg_a", true);  // 00 -> 11 within one period
  sim_.set_signal("mpg_b", true);
  EXPECT_EQ(period(sim_).counts[0], 4u);
  EXPECT_EQ(sim_.quadrature_errors(PanelCounter::mpg), 1u);
  phase_ = 2;  // 11: the wheel goes on from there
  EXPECT_EQ(turn(2), 6u);
}

TEST(SimPanelConfig, AnEncoderNeedsBothLines) {
  auto c = machine();
  c.panel.knobs[0].encoder.a = sim("feed_a");
  SimDriver sim;
  const std::string error = sim.configure(c, {});
  EXPECT_NE(error.find("FEED_OVERRIDE_A and FEED_OVERRIDE_B"), std::string::npos) << error;
}

// The panel's sim addresses make the sim driver; its evdev addresses are the evdev driver's.
TEST(SimPanelConfig, ThePanelsSimAddressesMakeTheSimDriver) {
  auto c = machine();
  EXPECT_TRUE(io_driver_names(c).empty());
  c.panel.lights[2] = sim("green");
  config::SignalAddress pendant;
  pendant.kind = config::SignalAddress::Kind::evdev;
  pendant.device = "/dev/input/event7";
  pendant.code = "KEY_F1";
  c.panel.inputs[1] = pendant;
  const auto names = io_driver_names(c);
  ASSERT_EQ(names.size(), 1u);
  EXPECT_STREQ(names[0], "sim");
}

}  // namespace
}  // namespace cncd::drivers
