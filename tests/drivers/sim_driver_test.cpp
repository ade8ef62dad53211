// The sim driver through the Driver interface: echo, lag, injected faults and switches.
#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "test_util.hpp"

namespace cncd::drivers {
namespace {

config::MachineConfig two_joints() {
  config::MachineConfig c;
  c.servo_period_ns = 1'000'000;
  c.joints.resize(2);
  c.joints[0].axis = 'X';
  c.joints[1].axis = 'Y';
  return c;
}

TEST(MakeDriver, SimIsAlwaysThere) {
  std::string error;
  const auto driver = make_driver("sim", error);
  ASSERT_NE(driver, nullptr) << error;
  EXPECT_STREQ(driver->name(), "sim");
  EXPECT_TRUE(driver->capabilities() & kCapHomeSwitch);
  EXPECT_FALSE(driver->capabilities() & kCapPositionFeedback);  // it only echoes
}

TEST(MakeDriver, UnknownNamesSayWhich) {
  std::string error;
  EXPECT_EQ(make_driver("stepper9000", error), nullptr);
  EXPECT_NE(error.find("'stepper9000'"), std::string::npos) << error;
}

TEST(SimDriver, ConfigureChecksItsJoints) {
  const auto config = two_joints();
  SimDriver sim;
  EXPECT_EQ(sim.configure(config, {0, 1}), "");
  EXPECT_NE(sim.configure(config, {0, 2}).find("joint 2"), std::string::npos);
  auto zero_period = config;
  zero_period.servo_period_ns = 0;
  EXPECT_NE(sim.configure(zero_period, {0}), "");
}

TEST(SimDriver, EchoesCommandsWithoutLag) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(two_joints(), {0, 1}), "");
  sim.enable();
  const JointCommand commands[2] = {{12.5, 0, true}, {-3, 0, true}};
  sim.write(commands, 2);
  JointFeedback feedback[2];
  sim.read(feedback, 2);
  EXPECT_EQ(feedback[0].position, 12.5);
  EXPECT_EQ(feedback[1].position, -3);
  EXPECT_FALSE(feedback[0].fault || feedback[0].stale || feedback[0].home_switch);
  MachineInputs inputs;
  sim.read_inputs(inputs);
  EXPECT_FALSE(inputs.estop);
  sim.disable();
}

TEST(SimDriver, LagIsFirstOrder) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(two_joints(), {0}), "");
  JointCommand command{0, 0, true};
  sim.write(&command, 1);  // the first write places the simulated motor
  sim.set_lag(0.010);
  command.position = 1;
  JointFeedback feedback;
  for (int n = 1; n <= 30; ++n) {
    sim.write(&command, 1);
    sim.read(&feedback, 1);
    EXPECT_NEAR(feedback.position, 1 - std::exp(-n * 0.001 / 0.010), 1e-12) << n;
  }
}

TEST(SimDriver, EachJointTakesItsLagFromTheIni) {
  test::TempDir dir;
  // Joint 0 gets SIM_LAG = 0.00, joint 1 SIM_LAG = 0.01.
  const auto loaded = test::load_machine(dir, 2, "DRIVER = sim\nSIM_LAG = 0.0{j}", "");
  ASSERT_TRUE(loaded.config);
  SimDriver sim;
  ASSERT_EQ(sim.configure(*loaded.config, {0, 1}), "");
  JointCommand commands[2] = {{0, 0, true}, {0, 0, true}};
  sim.write(commands, 2);
  commands[0].position = commands[1].position = 1;
  sim.write(commands, 2);
  JointFeedback feedback[2];
  sim.read(feedback, 2);
  EXPECT_EQ(feedback[0].position, 1.0);  // no SIM_LAG: an exact echo
  EXPECT_NEAR(feedback[1].position, 1 - std::exp(-0.001 / 0.01), 1e-12);
}

TEST(SimDriver, ABadLagNamesItsFileAndLine) {
  test::TempDir dir;
  ASSERT_TRUE(test::load_machine(dir, 2, "DRIVER = sim\nSIM_LAG = 0.5", "").config);
  std::ifstream in(dir.path() / "machine.ini");
  std::stringstream contents;
  contents << in.rdbuf();
  std::string text = contents.str();
  text.replace(text.find("SIM_LAG = 0.5"), 13, "SIM_LAG = slow");
  const auto loaded = config::load_machine_config(dir.write("lag.ini", text));
  ASSERT_TRUE(loaded.config);
  SimDriver sim;
  const std::string problem = sim.configure(*loaded.config, {0, 1});
  EXPECT_NE(problem.find("lag.ini:"), std::string::npos) << problem;
  EXPECT_NE(problem.find("[JOINT_0] SIM_LAG"), std::string::npos) << problem;
}

TEST(SimDriver, InjectedFaultsStaleFeedbackLimitsAndEstop) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(two_joints(), {0, 1}), "");
  JointCommand commands[2] = {{1, 0, true}, {2, 0, true}};
  sim.write(commands, 2);
  sim.set_fault(1, true);
  sim.set_stale(0, true);
  sim.set_limit(1, false, true);
  sim.set_estop_input(true);
  sim.set_fault(99, true);  // out of range: ignored
  commands[0].position = 5;
  sim.write(commands, 2);
  JointFeedback feedback[2];
  sim.read(feedback, 2);
  EXPECT_TRUE(feedback[0].stale);
  EXPECT_EQ(feedback[0].position, 1);  // stale feedback does not move
  EXPECT_TRUE(feedback[1].fault);
  char reason[64];
  EXPECT_TRUE(sim.fault_reason(reason, sizeof reason));
  EXPECT_STREQ(reason, "fault injected on simulated drive 1");
  EXPECT_TRUE(feedback[1].max_limit);
  EXPECT_FALSE(feedback[1].min_limit);
  MachineInputs inputs;
  sim.read_inputs(inputs);
  EXPECT_TRUE(inputs.estop);
  sim.set_stale(0, false);
  sim.set_fault(1, false);
  sim.read(feedback, 2);
  EXPECT_EQ(feedback[0].position, 5);
  EXPECT_FALSE(sim.fault_reason(reason, sizeof reason));
  EXPECT_STREQ(reason, "");
}

TEST(SimDriver, HomeSwitchSitsAtHomeOffsetInTheSearchDirection) {
  auto config = two_joints();
  config.joints[0].home_search_vel = 10;
  config.joints[0].home_offset = 20;
  config.joints[1].home_search_vel = -10;
  config.joints[1].home_offset = -5;
  SimDriver sim;
  ASSERT_EQ(sim.configure(config, {0, 1}), "");
  auto switches_at = [&](double p0, double p1) {
    const JointCommand commands[2] = {{p0, 0, true}, {p1, 0, true}};
    sim.write(commands, 2);
    JointFeedback feedback[2];
    sim.read(feedback, 2);
    return std::make_pair(feedback[0].home_switch, feedback[1].home_switch);
  };
  EXPECT_EQ(switches_at(0, 0), std::make_pair(false, false));
  EXPECT_EQ(switches_at(20, -5), std::make_pair(true, true));
  EXPECT_EQ(switches_at(25, -9), std::make_pair(true, true));
  EXPECT_EQ(switches_at(19.999, -4.999), std::make_pair(false, false));
  sim.set_home_switch(0, 0, -1);
  sim.set_home_switch(1, 0, 0);  // removed
  EXPECT_EQ(switches_at(-1, -100), std::make_pair(true, false));
}

// Injection from another thread while the servo side reads (run under TSan too).
TEST(SimDriver, InjectionFromAnotherThreadIsRaceFree) {
  SimDriver sim;
  ASSERT_EQ(sim.configure(two_joints(), {0, 1}), "");
  std::atomic<bool> done{false};
  std::thread injector([&] {
    for (int i = 0; i < 20'000; ++i) {
      sim.set_fault(i % 2, i % 3 == 0);
      sim.set_lag((i % 5) * 0.001);
      sim.set_home_switch(0, i * 0.01, i % 2 ? 1 : -1);
    }
    done = true;
  });
  const JointCommand commands[2] = {{1, 0, true}, {2, 0, true}};
  JointFeedback feedback[2];
  int cycles = 0;
  while (!done || cycles < 100) {
    sim.write(commands, 2);
    sim.read(feedback, 2);
    ASSERT_TRUE(std::isfinite(feedback[0].position));
    ++cycles;
  }
  injector.join();
}

}  // namespace
}  // namespace cncd::drivers
