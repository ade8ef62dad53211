// xyzac-trt-kins and xyzbc-trt-kins: the joints drive X Y Z A C (B C) one to one, and the
// tool-tip transform of TCP puts the part where the rotaries turn it and back.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/kinematics.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;

config::MachineConfig trunnion(const char* module, config::TableRotaryConfig geometry) {
  config::MachineConfig c;
  c.kinematics = module;
  const std::string letters = module[3] == 'a' ? "XYZAC" : "XYZBC";
  c.coordinates = letters;
  for (const char letter : letters) {
    auto& axis = c.axes[static_cast<std::size_t>(config::axis_index(letter))];
    axis.present = true;
    axis.max_velocity = 20;
    axis.max_acceleration = 300;
    config::JointConfig joint;
    joint.axis = letter;
    joint.max_velocity = 25;
    joint.max_acceleration = 350;
    c.joints.push_back(joint);
  }
  c.joint_count = 5;
  c.table_rotary = geometry;
  return c;
}

AxisPose pose(double x, double y, double z, double a, double b, double c) {
  return {x, y, z, a, b, c, 0, 0, 0};
}

void expect_pose(const AxisPose& got, const AxisPose& want, double tolerance = 1e-9) {
  for (std::size_t i = 0; i < got.size(); ++i)
    EXPECT_NEAR(got[i], want[i], tolerance) << "axis " << config::kAxisLetters[i];
}

TEST(TableRotaryKinsTest, JointsDriveTheirAxesOneToOne) {
  const auto kins = motion::make_kinematics(trunnion("xyzac-trt-kins", {}));
  EXPECT_TRUE(kins->has_tcp());
  motion::JointArray joints{};
  kins->inverse(pose(1, 2, 3, 4, 0, 6), motion::kAllAxes, joints);
  EXPECT_EQ(joints[3], 4);  // A
  EXPECT_EQ(joints[4], 6);  // C
  AxisPose axes{};
  kins->forward(joints, axes);
  expect_pose(axes, pose(1, 2, 3, 4, 0, 6), 0);
  EXPECT_EQ(kins->axis_of_joint(4), 5);
  EXPECT_EQ(kins->joints_of_axis(5), 1u << 4);
  // Each axis's limits and each joint's: ten bounds.
  EXPECT_EQ(kins->rate_limits().size(), static_cast<std::size_t>(motion::kAxes) + 5);
}

TEST(TableRotaryKinsTest, KnownPosesOfXyzac) {
  // LinuxCNC's sample geometry: the A axis 20 mm behind the C axis (+Y) and 10 mm above it.
  config::TableRotaryConfig g;
  g.y_offset = 20;
  g.z_offset = 10;
  const auto kins = motion::make_kinematics(trunnion("xyzac-trt-kins", g));
  AxisPose m{};
  // Every rotary at 0: the part's frame is the machine's.
  kins->tcp_inverse(pose(12, -7, 3, 0, 0, 0), 0, m);
  expect_pose(m, pose(12, -7, 3, 0, 0, 0));
  // C 90: the table turns a point on +X to +Y about the C axis (through the origin).
  kins->tcp_inverse(pose(10, 0, 0, 0, 0, 90), 0, m);
  expect_pose(m, pose(0, 10, 0, 0, 0, 90));
  // A 90: a point 10 mm above the A axis (Y 20, Z 10) swings to 10 mm before it (-Y).
  kins->tcp_inverse(pose(0, 20, 20, 90, 0, 0), 0, m);
  expect_pose(m, pose(0, 10, 10, 90, 0, 0));
  // A point on the A axis stays where it is, whatever A.
  kins->tcp_inverse(pose(5, 20, 10, -37, 0, 0), 0, m);
  expect_pose(m, pose(5, 20, 10, -37, 0, 0));
  // C then A: (10, 0, 0) goes to (0, 10, 0) by C, then about the A axis: 10 mm before it and
  // 10 mm below, turned 90 degrees: 10 mm below and 10 mm behind.
  kins->tcp_inverse(pose(10, 0, 0, 90, 0, 90), 0, m);
  expect_pose(m, pose(0, 30, 0, 90, 0, 90));
}

// xyzbc with the B axis 5 mm left of the C axis (X -5) and `tool_offset`.
std::unique_ptr<const motion::Kinematics> xyzbc(double tool_offset) {
  config::TableRotaryConfig g;
  g.x_offset = -5;
  g.tool_offset = tool_offset;
  return motion::make_kinematics(trunnion("xyzbc-trt-kins", g));
}

TEST(TableRotaryKinsTest, KnownPosesOfXyzbcAndTheToolOffset) {
  const auto kins = xyzbc(50);
  AxisPose m{};
  // B 90 about the B axis (X -5, Z 0): the tool tip at (5, 0, 0) in the part (the controlled
  // point 50 above it) goes to 10 mm below the axis, the controlled point 50 above that.
  kins->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 0, m);
  expect_pose(m, pose(-5, 0, 40, 0, 90, 0));
  // The tip on the B axis stays there.
  kins->tcp_inverse(pose(-5, 3, 50, 0, 33, 0), 0, m);
  expect_pose(m, pose(-5, 3, 50, 0, 33, 0));
}

TEST(TableRotaryKinsTest, TheG43LengthInForceIsTheToolsLengthElseToolOffset) {
  // LinuxCNC nets motion.tooloffset.z to the module's tool-offset pin: the G43 length in force
  // is the length the tip is turned with; [KINS] TOOL_OFFSET only stands in while none is.
  const auto kins = xyzbc(80);
  AxisPose m{};
  AxisPose as_offset{};
  // G43 with 50 mm: as TOOL_OFFSET 50 without G43, the tip (5, 0, 0) 10 mm below the B axis.
  kins->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 50, m);
  xyzbc(50)->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 0, as_offset);
  expect_pose(m, as_offset);
  // G49: TOOL_OFFSET's 80 mm; the tip at (5, 0, -30), 10 mm right of and 30 below the axis,
  // turned to 30 mm left of it and 10 below.
  kins->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 0, m);
  expect_pose(m, pose(-35, 0, 70, 0, 90, 0));
  AxisPose back{};
  kins->tcp_forward(m, 0, back);
  expect_pose(back, pose(5, 0, 50, 0, 90, 0));
  // With the tilting axis at 0 the length moves no joint, whatever C: G43 changes nothing
  // there but the program's Z.
  for (const double length : {0.0, 30.0, 50.0, -12.5}) {
    kins->tcp_inverse(pose(12, -7, 3, 0, 0, 77), length, m);
    AxisPose none{};
    kins->tcp_inverse(pose(12, -7, 3, 0, 0, 77), 80, none);
    expect_pose(m, none);
  }
  // Tilted, it does: the tip is length below the controlled point, and the cradle swings it.
  AxisPose longer{};
  kins->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 60, longer);
  kins->tcp_inverse(pose(5, 0, 50, 0, 90, 0), 50, m);
  // 10 mm longer: the controlled point stays 10 mm higher, the tip swung 10 mm toward -X.
  EXPECT_NEAR(longer[0] - m[0], -10, 1e-9);
  EXPECT_NEAR(longer[2] - m[2], 10, 1e-9);
}

TEST(TableRotaryKinsTest, ForwardUndoesInverseEverywhere) {
  config::TableRotaryConfig g;
  g.x_rot_point = 12.5;
  g.y_rot_point = -40;
  g.z_rot_point = 7;
  g.x_offset = 3;
  g.y_offset = 20;
  g.z_offset = 10;
  g.tool_offset = 80;
  std::mt19937 random(29);
  std::uniform_real_distribution<double> place(-300, 300);
  std::uniform_real_distribution<double> angle(-720, 720);
  std::uniform_real_distribution<double> tool(-20, 150);
  for (const char* module : {"xyzac-trt-kins", "xyzbc-trt-kins"}) {
    const auto kins = motion::make_kinematics(trunnion(module, g));
    double worst = 0;
    for (int k = 0; k < 10000; ++k) {
      const AxisPose part = pose(place(random), place(random), place(random), angle(random),
                                 angle(random), angle(random));
      // Every other pose with a G43 length, the others with TOOL_OFFSET.
      const double length = k % 2 == 0 ? tool(random) : 0.0;
      AxisPose machine{}, back{};
      kins->tcp_inverse(part, length, machine);
      kins->tcp_forward(machine, length, back);
      for (std::size_t i = 0; i < part.size(); ++i)
        worst = std::max(worst, std::abs(back[i] - part[i]));
    }
    EXPECT_LE(worst, 1e-9) << module;
  }
}

TEST(TableRotaryKinsTest, TrivkinsHasNoTcp) {
  config::MachineConfig c = trunnion("xyzac-trt-kins", {});
  c.kinematics = "trivkins";
  const auto kins = motion::make_kinematics(c);
  EXPECT_FALSE(kins->has_tcp());
  AxisPose m{};
  kins->tcp_inverse(pose(1, 2, 3, 40, 0, 50), 0, m);
  expect_pose(m, pose(1, 2, 3, 40, 0, 50), 0);
}

}  // namespace
}  // namespace cncd::test
