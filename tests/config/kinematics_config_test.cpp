// [KINS] KINEMATICS: trivkins, corexykins and the table-rotary modules load, every other module and
// every bad value is refused at its FILE:LINE with the section, the key and what is wrong.
#include <gtest/gtest.h>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

using KinematicsConfigTest = MachineIniTest;

// minimal_ini(): line 6 is [TRAJ] COORDINATES, 10 [KINS] KINEMATICS, 11 JOINTS, 28 and 29
// [JOINT_0] MIN_LIMIT and MAX_LIMIT, 33 and 34 [JOINT_1]'s. The motors' soft limits are left
// to the axes'.
std::string corexy_ini() {
  auto ini = replace_line(minimal_ini(), 10, "KINEMATICS = corexykins");
  for (const int line : {28, 29, 33, 34})
    ini = replace_line(ini, line, "# the motor's soft limit from the axes'");
  return ini;
}

TEST_F(KinematicsConfigTest, CorexyLoadsWithItsMotorsAsJointsZeroAndOne) {
  const auto result = load(corexy_ini());
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const MachineConfig& c = *result.config;
  EXPECT_EQ(c.kinematics, "corexykins");
  ASSERT_EQ(c.joints.size(), 3u);
  EXPECT_EQ(c.joints[0].axis, '\0');
  EXPECT_EQ(c.joints[1].axis, '\0');
  EXPECT_EQ(c.joints[2].axis, 'Z');
  // Its motors are no joints "driven by no axis", nor is X or Y an axis without joints.
  for (const auto& warning : strings(result.warnings)) {
    EXPECT_EQ(warning.find("driven by no"), std::string::npos) << warning;
  }
  EXPECT_NE(describe(c).find("X + Y (motor)"), std::string::npos) << describe(c);
}

TEST_F(KinematicsConfigTest, CorexyMotorLimitsNotGivenCoverTheAxes) {
  // X and Y both -10 .. 100: X + Y covers -20 .. 200 and X - Y -110 .. 110.
  const auto result = load(corexy_ini());
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->joints[0].min_limit, -20);
  EXPECT_EQ(result.config->joints[0].max_limit, 200);
  EXPECT_EQ(result.config->joints[1].min_limit, -110);
  EXPECT_EQ(result.config->joints[1].max_limit, 110);
  // Wider ones are kept as written.
  const auto wide = load(replace_line(corexy_ini(), 28, "MIN_LIMIT = -30"));
  ASSERT_TRUE(wide.ok()) << ::testing::PrintToString(strings(wide.problems));
  EXPECT_EQ(wide.config->joints[0].min_limit, -30);
}

TEST_F(KinematicsConfigTest, CorexyMotorLimitsNarrowerThanTheAxesAreRefused) {
  const std::string rule =
      " reaches within the X and Y limits; joint limits must include the "
      "axis limits";
  const auto problems = problems_of(
      replace_line(replace_line(corexy_ini(), 28, "MIN_LIMIT = -10"), 34, "MAX_LIMIT = 100"));
  ASSERT_EQ(problems.size(), 2u) << ::testing::PrintToString(problems);
  EXPECT_EQ(problems[0], at(28) +
                             ": [JOINT_0] MIN_LIMIT: -10 is narrower than the -20 that "
                             "this motor (X + Y)" +
                             rule);
  EXPECT_EQ(problems[1], at(34) +
                             ": [JOINT_1] MAX_LIMIT: 100 is narrower than the 110 that "
                             "this motor (X - Y)" +
                             rule);
}

TEST_F(KinematicsConfigTest, UnknownModuleIsRefused) {
  EXPECT_EQ(problems_with(10, "KINEMATICS = corexy"),
            problem_at(10,
                       "[KINS] KINEMATICS: kinematics 'corexy' is no kinematics module LinuxCNC or "
                       "cncd knows; cncd supports trivkins, corexykins, xyzac-trt-kins and "
                       "xyzbc-trt-kins"));
}

TEST_F(KinematicsConfigTest, LinuxCncModulesCncdLacksAreRefused) {
  for (const char* module : {"genhexkins", "scarakins", "5axiskins"}) {
    EXPECT_EQ(problems_with(10, std::string("KINEMATICS = ") + module + " coordinates=XYZAC"),
              problem_at(10, std::string("[KINS] KINEMATICS: kinematics '") + module +
                                 "' is not supported; cncd supports trivkins, corexykins, "
                                 "xyzac-trt-kins and xyzbc-trt-kins"));
  }
}

TEST_F(KinematicsConfigTest, EmptyValueIsRefused) {
  EXPECT_EQ(problems_with(10, "KINEMATICS ="),
            problem_at(10, "[KINS] KINEMATICS: no module named; write KINEMATICS = trivkins"));
}

TEST_F(KinematicsConfigTest, CorexyNeedsXAndY) {
  auto ini = replace_line(corexy_ini(), 6, "COORDINATES = X Z");
  ini = replace_line(ini, 11, "JOINTS = 3");
  EXPECT_EQ(problems_of(ini),
            problem_at(6,
                       "[TRAJ] COORDINATES: COORDINATES XZ has no Y, but corexykins moves X "
                       "and Y with joints 0 and 1"));
}

TEST_F(KinematicsConfigTest, CorexyHasNoGantry) {
  EXPECT_EQ(problems_of(replace_line(corexy_ini(), 6, "COORDINATES = X Y Y Z")),
            problem_at(6,
                       "[TRAJ] COORDINATES: Y is repeated, but corexykins drives each axis "
                       "with its own joints and has no gantry; write each letter once"));
}

TEST_F(KinematicsConfigTest, CorexyNeedsTwoJoints) {
  const auto problems = problems_of(replace_line(corexy_ini(), 11, "JOINTS = 1"));
  EXPECT_NE(std::find(problems.begin(), problems.end(),
                      at(11) + ": [KINS] JOINTS: JOINTS = 1 is too few: corexykins needs joints "
                               "0 and 1 for the X + Y and X - Y motors"),
            problems.end())
      << ::testing::PrintToString(problems);
}

TEST_F(KinematicsConfigTest, CorexyArgumentsAreIgnoredWithAWarning) {
  const auto result = load(replace_line(corexy_ini(), 10, "KINEMATICS = corexykins foo=1"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(
      any_contains(result.warnings,
                   at(10) + ": [KINS] KINEMATICS: unknown corexykins argument 'foo=1' ignored"));
}

TEST_F(KinematicsConfigTest, TrivkinsBadCoordinatesAreRefused) {
  EXPECT_EQ(problems_with(10, "KINEMATICS = trivkins coordinates=XQZ"),
            problem_at(10, "[KINS] KINEMATICS: coordinates=XQZ: 'Q' is not an axis letter"));
}

TEST_F(KinematicsConfigTest, TheTrunnionExampleLoadsWithItsGeometry) {
  const auto result =
      load_machine_config(std::string(CNCD_CONFIG_EXAMPLES_DIR) + "/sim_xyzac_trt.ini");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
  const MachineConfig& c = *result.config;
  EXPECT_EQ(c.kinematics, "xyzac-trt-kins");
  ASSERT_EQ(c.joints.size(), 5u);
  EXPECT_EQ(c.joints[3].axis, 'A');
  EXPECT_EQ(c.joints[4].axis, 'C');
  EXPECT_EQ(c.table_rotary.y_offset, 20);
  EXPECT_EQ(c.table_rotary.z_offset, 10);
  EXPECT_EQ(c.table_rotary.tcp_tolerance, 0.005);
}

TEST_F(KinematicsConfigTest, TableRotaryNeedsItsFiveAxes) {
  auto ini = replace_line(minimal_ini(), 10, "KINEMATICS = xyzbc-trt-kins");
  EXPECT_EQ(problems_of(ini),
            (std::vector<std::string>{
                problem_at(6,
                           "[TRAJ] COORDINATES: COORDINATES XYZ has no B, but xyzbc-trt-kins "
                           "moves XYZBC with joints 0 to 4")[0],
                problem_at(6,
                           "[TRAJ] COORDINATES: COORDINATES XYZ has no C, but xyzbc-trt-kins "
                           "moves XYZBC with joints 0 to 4")[0],
                problem_at(11,
                           "[KINS] JOINTS: JOINTS = 3 is too few: xyzbc-trt-kins needs joints 0 "
                           "to 4 for XYZBC")[0]}));
}

}  // namespace
}  // namespace cncd::config::test
