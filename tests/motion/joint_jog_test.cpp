// Joint-mode jogs in the servo loop, in virtual time: one motor of an unhomed gantry or corexy
// machine moves alone within its own limits and the axes follow the forward kinematics; an
// axis whose joints stand apart then refuses to jog (its twin would jump); a homed joint that
// moves with an axis refuses, one that is its axis alone jogs to its joint soft limit; joint and
// axis jogs exclude each other.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "cncd/motion/jog.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MotionState;

void jog(VirtualMachine& m, Command::Kind kind, bool joint, int index, double velocity,
         double distance = 0) {
  send_jog(m, kind, index, velocity, distance, joint);
}

// On, not homed.
void turn_on(VirtualMachine& m) {
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  m.cycles(2);
  m.clear_trajectory();
  drain_events(m);
}

config::MachineConfig gantry() {
  auto config = small_mill();
  config.coordinates = "XYYZ";
  config.joints.insert(config.joints.begin() + 2, config.joints[1]);  // a second Y motor
  config.joint_count = 4;
  config.joints[2].max_velocity = 50;  // the second motor slower than its axis
  config.joints[2].max_acceleration = 500;
  return config;
}

TEST(JointJog, AnUnhomedGantryMotorMovesAloneWithinItsOwnLimits) {
  VirtualMachine m(gantry());
  turn_on(m);
  jog(m, Command::Kind::jog_increment, true, 2, 1000, 5);
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.joint_commanded[2], 5);
  EXPECT_EQ(s.joint_commanded[1], 0);
  EXPECT_EQ(s.commanded[1], 0);  // Y is where its first joint is
  const Peaks p = joint_peaks(m);
  EXPECT_LE(p.velocity, 1.0 + 1e-9);
  EXPECT_LE(p.acceleration, 1.0 + 1e-9);
  EXPECT_GT(p.velocity, 0.99);  // at the second motor's 50 mm/s, not the axis's 200

  // Y now stands 5 mm from its second motor: a jog of Y would make that motor jump.
  jog(m, Command::Kind::jog_increment, false, 1, 100, 1);
  m.cycles(10);
  EXPECT_NE(drain_events(m).find(motion::kJointsApartForJog), std::string::npos);
  EXPECT_EQ(m.status().joint_commanded[2], 5);
  EXPECT_EQ(m.status().commanded[1], 0);
  // Back together, Y jogs again, both motors as one.
  jog(m, Command::Kind::jog_increment, true, 2, 50, -5);
  m.run_until_idle();
  jog(m, Command::Kind::jog_increment, false, 1, 100, 1);
  m.run_until_idle();
  EXPECT_EQ(m.status().joint_commanded[1], 1);
  EXPECT_EQ(m.status().joint_commanded[2], 1);
}

TEST(JointJog, AHomedGantryMotorRefusesAndAnAxisOfItsOwnStopsAtItsJointLimit) {
  VirtualMachine m(gantry());
  m.ready();
  drain_events(m);
  jog(m, Command::Kind::jog_start, true, 2, 10);
  m.cycles(10);
  EXPECT_NE(drain_events(m).find(motion::kHomedJointMovesWithAxis), std::string::npos);
  EXPECT_EQ(m.status().motion, MotionState::idle);
  EXPECT_EQ(m.status().joint_commanded[2], 0);

  // X is joint 0 alone: it jogs as a joint, up to the joint's soft limit.
  const double limit = m.config().joints[0].min_limit;
  jog(m, Command::Kind::jog_start, true, 0, -1000);
  EXPECT_EQ(m.status().motion, MotionState::jogging);
  // An axis jog waits for the joint jog, and the other way round.
  jog(m, Command::Kind::jog_start, false, 2, 10);
  EXPECT_NE(drain_events(m).find("a joint is jogging"), std::string::npos);
  m.run_until_idle();
  EXPECT_EQ(m.status().joint_commanded[0], limit);
  EXPECT_EQ(m.status().commanded[0], limit);
  jog(m, Command::Kind::jog_start, true, 0, -10);
  EXPECT_NE(drain_events(m).find("the joint is at its minimum soft limit"), std::string::npos);
  jog(m, Command::Kind::jog_start, false, 2, 10);
  jog(m, Command::Kind::jog_start, true, 0, 10);
  EXPECT_NE(drain_events(m).find("an axis is jogging"), std::string::npos);
  jog(m, Command::Kind::jog_stop, false, 2, 0);
  m.run_until_idle();
  jog(m, Command::Kind::jog_start, true, 7, 10);
  EXPECT_NE(drain_events(m).find("the machine has no such joint"), std::string::npos);
}

TEST(JointJog, ACorexyMotorMovesTheToolAlongADiagonal) {
  const auto loaded =
      config::load_machine_config(std::string(CNCD_SOURCE_DIR) + "/config/examples/sim_corexy.ini");
  ASSERT_TRUE(loaded.ok());
  VirtualMachine m(*loaded.config);
  turn_on(m);
  jog(m, Command::Kind::jog_increment, true, 0, 1000, 10);
  m.run_until_idle();
  auto s = m.status();
  EXPECT_EQ(s.joint_commanded[0], 10);
  EXPECT_EQ(s.joint_commanded[1], 0);
  EXPECT_NEAR(s.commanded[0], 5, 1e-12);  // X = (j0 + j1) / 2
  EXPECT_NEAR(s.commanded[1], 5, 1e-12);  // Y = (j0 - j1) / 2
  const Peaks p = joint_peaks(m);
  EXPECT_LE(p.velocity, 1.0 + 1e-9);
  EXPECT_LE(p.acceleration, 1.0 + 1e-9);
  // X jogs on from there: both motors turn, the tool moves along X alone.
  jog(m, Command::Kind::jog_increment, false, 0, 100, 2);
  m.run_until_idle();
  s = m.status();
  EXPECT_NEAR(s.commanded[0], 7, 1e-12);
  EXPECT_NEAR(s.commanded[1], 5, 1e-12);
  // Homed, a motor moves two axes: refused.
  m.command(Command::Kind::home, 0xFFFFFFFFu);
  m.run_until_idle();
  drain_events(m);
  jog(m, Command::Kind::jog_start, true, 1, 10);
  EXPECT_NE(drain_events(m).find(motion::kHomedJointMovesWithAxis), std::string::npos);
}

}  // namespace
}  // namespace cncd::test
