// The corexy example machine (config/examples/sim_corexy.ini): its motors move as (X + Y,
// X - Y), the tool ends where the program puts it, and no motor is ever asked for more than
// its MAX_VELOCITY or MAX_ACCELERATION, even where one motor alone carries a diagonal.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/kinematics.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Move;

config::MachineConfig corexy_machine() {
  const auto result =
      config::load_machine_config(std::string(CNCD_SOURCE_DIR) + "/config/examples/sim_corexy.ini");
  EXPECT_TRUE(result.ok()) << (result.problems.empty() ? "" : result.problems[0].to_string());
  return result.ok() ? *result.config : config::MachineConfig{};
}

// On, homed where it stands (the origin), then at (x, y, 0) with the records cleared.
void ready_at(VirtualMachine& m, double x, double y) {
  m.ready();
  m.queue(line_to(Move::Kind::traverse, x, y, 0));
  m.run_until_idle();
  m.cycles(2);  // at rest: the next move's first periods differ from these by its own speed
  m.clear_trajectory();
}

TEST(CorexyTest, TheKinematicsTurnAxesIntoMotorsAndBack) {
  const auto config = corexy_machine();
  const auto kins = motion::make_kinematics(config);
  motion::JointArray joints{};
  kins->inverse({30, 20, -5, 0, 0, 0, 0, 0, 0}, motion::kAllAxes, joints);
  EXPECT_EQ(joints[0], 50);  // X + Y
  EXPECT_EQ(joints[1], 10);  // X - Y
  EXPECT_EQ(joints[2], -5);  // Z
  motion::AxisPose axes{};
  kins->forward(joints, axes);
  EXPECT_EQ(axes[0], 30);
  EXPECT_EQ(axes[1], 20);
  EXPECT_EQ(axes[2], -5);
  EXPECT_EQ(kins->joints_of_axis(0), 0b011u);
  EXPECT_EQ(kins->joints_of_axis(1), 0b011u);
  EXPECT_EQ(kins->joints_of_axis(2), 0b100u);
  EXPECT_EQ(kins->axis_of_joint(0), -1);
  EXPECT_EQ(kins->axis_of_joint(2), 2);
}

TEST(CorexyTest, ASquareMovesTheMotorsAsXPlusYAndXMinusYAndEndsWhereItShould) {
  VirtualMachine m(corexy_machine());
  ready_at(m, 50, 50);
  for (const auto& [x, y] : {std::pair{150.0, 50.0}, {150.0, 150.0}, {50.0, 150.0}, {50.0, 50.0}})
    m.queue(line_to(Move::Kind::feed, x, y, 0, 100));
  m.run_until_idle();
  const auto& axes = m.trajectory();
  const auto& motors = m.motor_trajectory();
  ASSERT_EQ(axes.size(), motors.size());
  ASSERT_GT(axes.size(), 4000u);  // 400 mm at 100 mm/s
  double worst = 0;
  bool moved_x_alone = false;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    worst = std::max(worst, std::abs(motors[k][0] - (axes[k][0] + axes[k][1])));
    worst = std::max(worst, std::abs(motors[k][1] - (axes[k][0] - axes[k][1])));
    // Along X both motors turn the same way; along Y against each other.
    if (k > 0 && std::abs(axes[k][1] - 50) < 1e-12 && axes[k][0] > 60 && axes[k][0] < 140) {
      EXPECT_NEAR(motors[k][0] - motors[k - 1][0], motors[k][1] - motors[k - 1][1], 1e-9);
      moved_x_alone = true;
    }
  }
  EXPECT_TRUE(moved_x_alone);
  EXPECT_LE(worst, 1e-9);
  const motion::Status s = m.status();
  EXPECT_NEAR(s.commanded[0], 50, 1e-9);
  EXPECT_NEAR(s.commanded[1], 50, 1e-9);
  EXPECT_NEAR(s.actual[0], 50, 1e-9);  // from the motors' feedback
  EXPECT_NEAR(s.actual[1], 50, 1e-9);
  EXPECT_NEAR(s.joint_commanded[0], 100, 1e-9);
  EXPECT_NEAR(s.joint_commanded[1], 0, 1e-9);
  EXPECT_NEAR(m.motor_position(0), 100, 1e-9);
  EXPECT_NEAR(m.motor_position(1), 0, 1e-9);
}

TEST(CorexyTest, ADiagonalKeepsTheMotorThatCarriesItWithinItsLimits) {
  VirtualMachine m(corexy_machine());
  ready_at(m, 10, 10);
  // Along X + Y only joint 0 turns, sqrt(2) times as fast as the tool: a traverse that the
  // axes alone would allow at 250 mm/s each (353 mm/s along the diagonal).
  m.queue(line_to(Move::Kind::traverse, 190, 190, 0));
  m.run_until_idle();
  expect_joints_within_limits(m, "diagonal traverse");
  const Peaks p = joint_peaks(m);
  // ... and it is the motor's limit that bounds the move, not a margin below it.
  EXPECT_GT(p.velocity, 0.999);
  EXPECT_GT(p.acceleration, 0.99);
  EXPECT_NEAR(m.motor_position(1), 0, 1e-9);  // joint 1 stood still
  expect_within_limits(m, {10, 10, 0, 0, 0, 0, 0, 0, 0});
}

TEST(CorexyTest, ArcsAndBlendedCornersKeepEveryMotorWithinItsLimits) {
  VirtualMachine m(corexy_machine());
  ready_at(m, 100, 50);
  // A full circle at a feed the axes alone would allow, then a zigzag blended within 0.5 mm.
  Move circle;
  circle.kind = Move::Kind::arc;
  circle.end = {100, 50, 0, 0, 0, 0, 0, 0, 0};
  circle.plane_axes = {0, 1, 2};
  circle.center_first = 150;
  circle.center_second = 100;
  circle.feed = 250;
  m.queue(circle);
  for (int k = 1; k <= 6; ++k) {
    Move zig = line_to(Move::Kind::feed, 100 + 25 * k, k % 2 == 0 ? 50 : 90, 0, 250);
    zig.path_mode = Move::PathMode::blend;
    zig.tolerance = 0.5;
    m.queue(zig);
  }
  m.run_until_idle();
  expect_joints_within_limits(m, "circle and zigzag");
  const motion::Status s = m.status();
  EXPECT_NEAR(s.commanded[0], 250, 1e-9);
  EXPECT_NEAR(s.commanded[1], 50, 1e-9);
}

TEST(CorexyTest, JogsMoveBothMotorsWithinTheirLimitsAndOneCoupledAxisAtATime) {
  VirtualMachine m(corexy_machine());
  ready_at(m, 100, 100);
  motion::Command jog{motion::Command::Kind::jog_increment};
  jog.axis = 0;
  jog.distance = 50;
  jog.velocity = 1000;  // capped at the axis's 250 mm/s
  m.send(jog);
  motion::Command y = jog;
  y.axis = 1;
  m.send(y);  // refused: X jogs, and X and Y share both motors
  EXPECT_EQ(m.status().motion, motion::MotionState::jogging);
  m.run_until_idle();
  const motion::Status s = m.status();
  EXPECT_NEAR(s.commanded[0], 150, 1e-9);
  EXPECT_NEAR(s.commanded[1], 100, 1e-9);
  EXPECT_NEAR(s.joint_commanded[0], 250, 1e-9);
  EXPECT_NEAR(s.joint_commanded[1], 50, 1e-9);
  expect_joints_within_limits(m, "jog of X");
}

}  // namespace
}  // namespace cncd::test
