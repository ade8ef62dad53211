// The sim driver's spindle and `sim:NAME` signals through write_io/read_io.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/sim_driver.hpp"

namespace cncd::drivers {
namespace {

config::SignalAddress sim(const std::string& name) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::sim;
  a.name = name;
  a.text = "sim:" + name;
  return a;
}

config::MachineConfig machine(double acceleration) {
  config::MachineConfig c;
  c.servo_period_ns = 1'000'000;
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::sim;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.acceleration = acceleration;
  return c;
}

// Runs `periods` servo periods with the same command; returns the last feedback.
IoFeedback run(SimDriver& sim, const IoCommand& command, int periods) {
  IoFeedback feedback;
  for (int i = 0; i < periods; ++i) {
    sim.write_io(command);
    feedback = IoFeedback{};
    sim.read_io(feedback);
  }
  return feedback;
}

IoCommand spindle(bool enable, bool reverse, double rpm) {
  IoCommand c;
  c.spindle = SpindleCommand{enable, reverse, rpm};
  return c;
}

TEST(SimSpindle, WithoutAccelerationItIsAtSpeedAtOnce) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(machine(0), {}), "");
  IoFeedback fb = run(sim, spindle(true, false, 1200), 1);
  EXPECT_TRUE(fb.spindle.present);
  EXPECT_TRUE(fb.spindle.has_position);
  EXPECT_FALSE(fb.spindle.has_at_speed);
  EXPECT_DOUBLE_EQ(fb.spindle.rpm, 1200);
  // 1200 rpm = 20 rev/s: one more second gives 20 revolutions more.
  const double before = fb.spindle.revolutions;
  fb = run(sim, spindle(true, false, 1200), 1000);
  EXPECT_NEAR(fb.spindle.revolutions - before, 20, 1e-9);
  fb = run(sim, spindle(false, false, 1200), 1);
  EXPECT_DOUBLE_EQ(fb.spindle.rpm, 0);
}

// A reading answers the command the period it was taken in ran with, never a newer one;
// while the feedback is stale nothing is simulated and nothing newer is answered.
TEST(SimSpindle, AReadingAcknowledgesTheCommandItsPeriodRanWith) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(machine(3000), {}), "");
  IoCommand c = spindle(true, false, 1350);
  c.spindle.sequence = 7;
  IoFeedback fb;
  sim.read_io(fb);
  EXPECT_EQ(fb.spindle.acknowledged, 0u);  // no command yet
  fb = run(sim, c, 1);
  EXPECT_EQ(fb.spindle.acknowledged, 7u);
  c.spindle.sequence = 8;
  c.spindle.reverse = true;
  sim.set_spindle_stale(true);
  fb = run(sim, c, 5);
  EXPECT_EQ(fb.spindle.acknowledged, 7u);
  sim.set_spindle_stale(false);
  fb = run(sim, c, 1);
  EXPECT_EQ(fb.spindle.acknowledged, 8u);
}

TEST(SimSpindle, RampsAtItsAccelerationAndReversesThroughZero) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(machine(1000), {}), "");  // 1000 rpm/s: 1 rpm per 1 ms period
  IoFeedback fb = run(sim, spindle(true, false, 600), 300);
  EXPECT_NEAR(fb.spindle.rpm, 300, 1e-6);
  fb = run(sim, spindle(true, false, 600), 300);
  EXPECT_NEAR(fb.spindle.rpm, 600, 1e-6);
  fb = run(sim, spindle(true, false, 600), 100);
  EXPECT_NEAR(fb.spindle.rpm, 600, 1e-6);  // holds
  // M4 at the same speed: down through 0 (600 ms), then up in reverse.
  fb = run(sim, spindle(true, true, 600), 599);
  EXPECT_NEAR(fb.spindle.rpm, 1, 1e-6);
  const double turned = fb.spindle.revolutions;
  fb = run(sim, spindle(true, true, 600), 301);
  EXPECT_NEAR(fb.spindle.rpm, 300, 1e-6);
  EXPECT_LT(fb.spindle.revolutions, turned);  // turning backwards now
  // Disabled: ramps down to 0 and stays there.
  fb = run(sim, spindle(false, true, 600), 400);
  EXPECT_NEAR(fb.spindle.rpm, 0, 1e-6);
}

TEST(SimSpindle, InjectedFaultsAndStaleFeedbackShowWithAReason) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(machine(0), {}), "");
  char text[kFaultReasonSize];
  EXPECT_FALSE(sim.fault_reason(text, sizeof text));
  sim.set_spindle_fault(true);
  IoFeedback fb = run(sim, spindle(true, false, 100), 1);
  EXPECT_TRUE(fb.spindle.fault);
  ASSERT_TRUE(sim.fault_reason(text, sizeof text));
  EXPECT_NE(std::string(text).find("spindle"), std::string::npos) << text;
  sim.set_spindle_fault(false);
  sim.set_spindle_stale(true);
  fb = run(sim, spindle(true, false, 100), 1);
  EXPECT_FALSE(fb.spindle.fault);
  EXPECT_TRUE(fb.spindle.stale);
  EXPECT_FALSE(sim.fault_reason(text, sizeof text));
}

TEST(SimSpindle, LeavesTheSpindleAloneWhenAnotherDriverHasIt) {
  auto config = machine(0);
  config.spindle.driver = config::SpindleDriver::modbus;
  SimDriver sim;
  ASSERT_EQ(sim.configure(config, {}), "");
  const IoFeedback fb = run(sim, spindle(true, false, 1200), 3);
  EXPECT_FALSE(fb.spindle.present);
  EXPECT_EQ(fb.spindle.rpm, 0);
}

TEST(SimSignals, OutputsAreReadAndInputsSetByName) {
  auto config = machine(0);
  config.spindle.present = false;
  config.io.flood = sim("coolant");
  config.io.mist = sim("mist");
  config.io.digital_outputs[3] = sim("clamp");
  config.io.analog_outputs[1] = sim("laser_power");
  config.io.digital_inputs[5] = sim("door_closed");
  config.io.analog_inputs[2] = sim("pressure");
  SimDriver sim;
  ASSERT_EQ(sim.configure(config, {}), "");
  IoCommand c;
  c.flood = true;
  c.digital = 1u << 3;
  c.analog[1] = 42.5;
  IoFeedback fb = run(sim, c, 1);
  EXPECT_TRUE(sim.signal_on("coolant"));
  EXPECT_FALSE(sim.signal_on("mist"));
  EXPECT_TRUE(sim.signal_on("clamp"));
  EXPECT_EQ(sim.signal_value("laser_power"), 42.5);
  EXPECT_EQ(sim.signal_value("nothing"), std::nullopt);
  EXPECT_FALSE(fb.spindle.present);
  EXPECT_EQ(fb.digital, 0u);

  EXPECT_TRUE(sim.set_signal("door_closed", true));
  EXPECT_TRUE(sim.set_signal("pressure", 6.25));
  EXPECT_FALSE(sim.set_signal("nothing", 1));
  fb = IoFeedback{};
  fb.digital = 1u;  // a bit another driver owns stays
  sim.read_io(fb);
  EXPECT_EQ(fb.digital, (1u << 5) | 1u);
  EXPECT_EQ(fb.analog[2], 6.25);
  sim.set_signal("door_closed", false);
  fb.digital = ~0u;
  sim.read_io(fb);
  EXPECT_EQ(fb.digital, ~(1u << 5));

  c.flood = false;
  c.digital = 0;
  run(sim, c, 1);
  EXPECT_FALSE(sim.signal_on("coolant"));
  EXPECT_FALSE(sim.signal_on("clamp"));
}

TEST(SimSignals, TheProbeInputIsASignal) {
  auto config = machine(0);
  config.io.probe_input = sim("probe");
  SimDriver sim;
  ASSERT_EQ(sim.configure(config, {}), "");
  drivers::MachineInputs in;
  sim.read_inputs(in);
  EXPECT_FALSE(in.probe);
  EXPECT_TRUE(sim.set_signal("probe", true));
  sim.read_inputs(in);
  EXPECT_TRUE(in.probe);
}

TEST(SimSignals, AnOutputAndAnInputOfOneNameAreWiredTogether) {
  auto config = machine(0);
  config.io.digital_outputs[0] = sim("loop");
  config.io.digital_inputs[7] = sim("loop");
  SimDriver sim;
  ASSERT_EQ(sim.configure(config, {}), "");
  IoCommand c;
  c.digital = 1u;
  EXPECT_EQ(run(sim, c, 1).digital, 1u << 7);
  c.digital = 0;
  EXPECT_EQ(run(sim, c, 1).digital, 0u);
}

TEST(SimSignals, MakeDriversCreatesTheSimDriverForASimSpindleAlone) {
  auto config = machine(0);
  config.spindle.driver = config::SpindleDriver::sim;
  std::string error;
  auto drivers = make_drivers(config, error);
  ASSERT_EQ(error, "");
  ASSERT_EQ(drivers.size(), 1u);
  EXPECT_STREQ(drivers[0].driver->name(), "sim");
  EXPECT_TRUE(drivers[0].joints.empty());
}

}  // namespace
}  // namespace cncd::drivers
