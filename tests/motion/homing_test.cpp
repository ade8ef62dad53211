// Homing in virtual time with the sim driver's home switches: LinuxCNC's sequences, position
// redefined without moving the motor, sequences and synchronised final moves, aborts.
#include <cmath>
#include <cstring>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MachineState;
using motion::MotionState;
using motion::Move;

void start_homing(VirtualMachine& m, std::uint32_t mask) {
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  m.clear_trajectory();
  m.command(Command::Kind::home, mask);
}

// Largest motor acceleration over the recorded trajectory, as a ratio of the joint's limit.
double peak_acceleration_ratio(const VirtualMachine& m, int j) {
  const auto& t = m.motor_trajectory();
  const double dt = m.period_s();
  double peak = 0;
  for (std::size_t k = 2; k < t.size(); ++k) {
    const double a = (t[k][j] - 2 * t[k - 1][j] + t[k - 2][j]) / (dt * dt);
    peak = std::max(peak,
                    std::abs(a) / m.config().joints[static_cast<std::size_t>(j)].max_acceleration);
  }
  return peak;
}

TEST(Homing, ImmediateHomingRenamesThePositionWithoutMovingTheMotor) {
  auto config = small_mill();
  config.joints[0].home_offset = 100;  // where the joint stands is called 100 ...
  config.joints[0].home = 90;          // ... then it moves to 90: 10 back
  VirtualMachine m(config);
  m.sim().set_lag(0.002);  // a jump of 100 would trip the following error
  start_homing(m, 1);
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::on) << s.fault_reason;
  EXPECT_TRUE(s.homed[0]);
  EXPECT_FALSE(s.homed[1]);
  EXPECT_EQ(s.joint_commanded[0], 90);
  EXPECT_EQ(s.commanded[0], 90);
  EXPECT_NEAR(m.motor_position(0), -10, 1e-9);
  EXPECT_LE(peak_acceleration_ratio(m, 0), 1.001);
}

struct SwitchCase {
  const char* name;
  double search_vel;
  double latch_vel;
  double home_offset;  // also where the sim's switch sits (motor position)
};

void PrintTo(const SwitchCase& c, std::ostream* os) {
  *os << c.name;
}

class SwitchHoming : public ::testing::TestWithParam<SwitchCase> {};

TEST_P(SwitchHoming, LatchesTheSwitchAndEndsAtHome) {
  const SwitchCase c = GetParam();
  auto config = small_mill();
  auto& joint = config.joints[0];
  joint.home_search_vel = c.search_vel;
  joint.home_latch_vel = c.latch_vel;
  joint.home_offset = c.home_offset;
  joint.home = 5;
  joint.home_final_vel = 20;
  VirtualMachine m(config);
  start_homing(m, 1);
  EXPECT_EQ(m.status().motion, MotionState::homing);
  m.run_until_idle(200'000);
  const auto s = m.status();
  ASSERT_EQ(s.machine, MachineState::on) << s.fault_reason;
  EXPECT_TRUE(s.homed[0]);
  EXPECT_EQ(s.joint_commanded[0], 5);
  // The switch edge (motor position HOME_OFFSET) was named HOME_OFFSET, to within one
  // period's travel at the latch velocity, so the motor ends at HOME.
  EXPECT_NEAR(m.motor_position(0), 5, std::abs(c.latch_vel) * 1e-3);
  EXPECT_LE(peak_acceleration_ratio(m, 0), 1.001);
  // The search was at the search velocity, not faster.
  double peak_v = 0;
  const auto& t = m.motor_trajectory();
  for (std::size_t k = 1; k < t.size(); ++k)
    peak_v = std::max(peak_v, std::abs(t[k][0] - t[k - 1][0]) / m.period_s());
  EXPECT_LE(peak_v, std::max(std::abs(c.search_vel), 20.0) * 1.001);
}

INSTANTIATE_TEST_SUITE_P(Directions, SwitchHoming,
                         ::testing::Values(SwitchCase{"RisingEdge", 50, 5, 20},
                                           SwitchCase{"FallingEdge", 50, -5, 20},
                                           SwitchCase{"NegativeSearch", -50, -2, -30},
                                           SwitchCase{"StartsOnTheSwitch", 50, 5, -10}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(Homing, SwitchNeverFoundFails) {
  auto config = small_mill();
  config.joints[0].home_search_vel = 100;
  config.joints[0].home_latch_vel = 5;
  config.joints[0].min_limit = -50;
  config.joints[0].max_limit = 50;
  VirtualMachine m(config);
  m.sim().set_home_switch(0, 0, 0);  // no switch
  start_homing(m, 1);
  m.run_until_idle(10'000);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_FALSE(s.homed[0]);
  EXPECT_NE(std::strstr(s.fault_reason, "joint 0: home switch not found"), nullptr)
      << s.fault_reason;
}

TEST(Homing, ImpossibleConfigurationsAreRefusedBeforeMoving) {
  auto config = small_mill();
  config.joints[1].home_search_vel = 10;  // no HOME_LATCH_VEL
  config.joints[2].home_latch_vel = 10;   // no HOME_SEARCH_VEL
  VirtualMachine m(config);
  start_homing(m, 2);
  EXPECT_NE(std::strstr(m.status().fault_reason, "joint 1: invalid homing config"), nullptr)
      << m.status().fault_reason;
  m.command(Command::Kind::on);
  m.command(Command::Kind::home, 4);
  EXPECT_NE(std::strstr(m.status().fault_reason, "joint 2: invalid homing config"), nullptr)
      << m.status().fault_reason;
  EXPECT_EQ(m.status().joint_commanded[0], 0);
}

TEST(Homing, AbortStopsUnderControlAndLeavesTheJointUnhomed) {
  auto config = small_mill();
  config.joints[0].home_search_vel = 150;
  config.joints[0].home_latch_vel = 5;
  config.joints[0].home_offset = 500;
  VirtualMachine m(config);
  start_homing(m, 1);
  m.cycles(400);  // settled, accelerated, cruising towards the switch
  EXPECT_GT(m.status().joint_commanded[0], 10);
  m.command(Command::Kind::abort);
  EXPECT_EQ(m.status().motion, MotionState::stopping);
  m.run_until_idle(1000);
  const auto s = m.status();
  EXPECT_EQ(s.machine, MachineState::on);
  EXPECT_FALSE(s.homed[0]);
  EXPECT_LE(peak_acceleration_ratio(m, 0), 1.001);
  motion::Event event;
  bool reported = false;
  while (m.loop().events().pop(event))
    reported = reported || std::strcmp(event.text, "homing aborted") == 0;
  EXPECT_TRUE(reported);
}

// Index of the period in which joint `j` starts its final move towards HOME (below its
// latch point): the motor's first negative step after its last positive one.
std::size_t final_move_start(const VirtualMachine& m, int j) {
  const auto& t = m.motor_trajectory();
  std::size_t last_positive = 0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    if (t[k][j] > t[k - 1][j]) last_positive = k;
  }
  for (std::size_t k = last_positive + 1; k < t.size(); ++k) {
    if (t[k][j] < t[k - 1][j]) return k;
  }
  return t.size();
}

config::MachineConfig gantry(bool synchronised) {
  auto config = small_mill();
  config.coordinates = "XYYZ";
  config.joints.insert(config.joints.begin() + 2, config.joints[1]);  // a second Y motor
  config.joint_count = 4;
  for (int j : {1, 2}) {
    auto& joint = config.joints[static_cast<std::size_t>(j)];
    joint.home_search_vel = 40;
    joint.home_latch_vel = 4;
    joint.home_offset = 20;
    joint.home = 0;
    joint.home_sequence = 1;
    joint.home_sequence_sync = synchronised;
  }
  return config;
}

TEST(Homing, SynchronisedSequenceStartsItsFinalMovesTogether) {
  for (const bool synchronised : {true, false}) {
    VirtualMachine m(gantry(synchronised));
    m.sim().set_home_switch(2, 35, 1);  // the second motor's switch is 15 further out
    start_homing(m, 1u << 1);           // asking for one joint of a synchronised pair homes both
    m.run_until_idle(200'000);
    const auto s = m.status();
    ASSERT_EQ(s.machine, MachineState::on) << s.fault_reason;
    EXPECT_EQ(s.homed[2], synchronised);
    if (!synchronised) continue;
    EXPECT_TRUE(s.homed[1]);
    EXPECT_EQ(s.commanded[1], 0);
    EXPECT_EQ(final_move_start(m, 1), final_move_start(m, 2));
    // Each motor stands HOME - HOME_OFFSET from its own switch: the gantry is squared.
    EXPECT_NEAR(m.motor_position(1), 20 - 20, 4e-3);
    EXPECT_NEAR(m.motor_position(2), 35 - 20, 4e-3);
  }
}

TEST(Homing, ARackedGantryHomesSquareThenMovesAsOne) {
  VirtualMachine m(gantry(true));
  m.sim().set_home_switch(2, 35, 1);  // racked: the second motor's switch is 15 further out
  start_homing(m, 1u << 1);
  m.run_until_idle(200'000);
  ASSERT_EQ(m.status().machine, MachineState::on) << m.status().fault_reason;
  const double first = m.motor_position(1);
  const double second = m.motor_position(2);
  EXPECT_NEAR(second - first, 15, 4e-3);  // each joint HOME - HOME_OFFSET from its switch
  // Both joints now stand at Y 0: a move of Y turns both motors by the same distance.
  m.queue(line_to(Move::Kind::feed, 0, 30, 0, 600));
  m.run_until_idle();
  const auto s = m.status();
  EXPECT_EQ(s.joint_commanded[1], 30);
  EXPECT_EQ(s.joint_commanded[2], 30);
  EXPECT_NEAR(m.motor_position(1) - first, 30, 1e-9);
  EXPECT_NEAR(m.motor_position(2) - second, 30, 1e-9);
}

TEST(Homing, SequencesRunInOrder) {
  auto config = gantry(false);
  config.joints[3].home_sequence = 0;  // Z first, immediate
  config.joints[0].home_sequence = 2;  // X last, immediate
  VirtualMachine m(config);
  start_homing(m, 0xFFFFFFFFu);
  int z_homed = -1, y_homed = -1, x_homed = -1;
  for (int cycle = 0; cycle < 200'000 && x_homed < 0; ++cycle) {
    m.cycles(1);
    const auto s = m.status();
    ASSERT_EQ(s.machine, MachineState::on) << s.fault_reason;
    if (z_homed < 0 && s.homed[3]) z_homed = cycle;
    if (y_homed < 0 && s.homed[1] && s.homed[2]) y_homed = cycle;
    if (x_homed < 0 && s.homed[0]) x_homed = cycle;
  }
  EXPECT_GE(z_homed, 0);
  EXPECT_GT(y_homed, z_homed);
  EXPECT_GT(x_homed, y_homed);
}

}  // namespace
}  // namespace cncd::test
