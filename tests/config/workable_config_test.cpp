// A configuration that loads must be able to run the machine: settings that contradict each
// other are refused at their FILE:LINE, slips that LinuxCNC tolerates are warned about there.
#include <gtest/gtest.h>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

using WorkableConfigTest = MachineIniTest;

TEST_F(WorkableConfigTest, HomeOutsideTheJointLimitsIsRefused) {
  EXPECT_EQ(problems_with(31, "MAX_ACCELERATION = 500\nHOME = 150"),
            problem_at(32,
                       "[JOINT_0] HOME: 150 is above MAX_LIMIT 100: homing would leave the joint "
                       "beyond its soft limit"));
  // Joint limits not given are the axis limits; HOME not given is 0.
  auto ini = replace_line(minimal_ini(), 13, "MIN_LIMIT = 10");
  ini = replace_line(ini, 28, "");
  EXPECT_EQ(problems_of(ini),
            std::vector<std::string>{at(27) + ": [JOINT_0] HOME: 0 (the default) is below [AXIS_X] "
                                              "MIN_LIMIT 10: homing would leave the joint beyond "
                                              "its soft limit"});
}

TEST_F(WorkableConfigTest, HomeOffsetBeyondALimitIsTheSwitchPosition) {
  // LinuxCNC's shipped configs put the home switch just past the end of travel: the joint
  // homes there and then moves to HOME, inside the limits.
  const auto result =
      load(replace_line(minimal_ini(), 31, "MAX_ACCELERATION = 500\nHOME_OFFSET = 101\nHOME = 99"));
  EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
}

TEST_F(WorkableConfigTest, RepeatedCoordinateLetterWithOneJointAnAxisIsRefused) {
  EXPECT_EQ(problems_of(replace_line(minimal_ini(), 6, "COORDINATES = X Y Y Z")),
            std::vector<std::string>{
                at(6) + ": [TRAJ] COORDINATES: Y is repeated, but a repeated letter is a gantry, "
                        "one joint a letter (4), and JOINTS = 3 gives each axis one joint; write "
                        "each letter once, or JOINTS = 4 for a gantry"});
  // trivkins coordinates= says which joints there are; COORDINATES cannot add one.
  EXPECT_EQ(problems_of(replace_line(replace_line(minimal_ini(), 6, "COORDINATES = X Y Y Z"), 10,
                                     "KINEMATICS = trivkins coordinates=XYZ")),
            std::vector<std::string>{at(6) + ": [TRAJ] COORDINATES: Y is written 2 times, but "
                                             "trivkins coordinates=XYZ drives it with 1 joint; a "
                                             "gantry repeats the letter in both"});
}

TEST_F(WorkableConfigTest, GantryLoads) {
  auto ini = replace_line(minimal_ini(), 6, "COORDINATES = X Y Y Z");
  ini = replace_line(ini, 10, "KINEMATICS = trivkins coordinates=XYYZ kinstype=both");
  ini = replace_line(ini, 11, "JOINTS = 4");
  ini += "[JOINT_3]\nMIN_LIMIT = -10\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n";
  const auto result = load(ini);
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->joints[2].axis, 'Y');
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
}

TEST_F(WorkableConfigTest, JointOfAnAxisWithoutItsSectionIsRefused) {
  // [JOINT_2] written as [JOINT_3]: LinuxCNC would drive Z at 1 mm/s without joint limits.
  EXPECT_EQ(problems_with(37, "[JOINT_3]"),
            problem_at(11,
                       "[KINS] JOINTS: JOINTS = 3, but joint 2 (axis Z) has no [JOINT_2] section; "
                       "the file has [JOINT_3] instead, which JOINTS leaves out"));
  // A lathe converted from LinuxCNC 2.7 keeps a joint for the Y it does not have: a warning.
  const auto lathe =
      load(replace_line(replace_line(minimal_ini(), 6, "COORDINATES = X Z"), 32, "[SPARE]"));
  ASSERT_TRUE(lathe.ok()) << ::testing::PrintToString(strings(lathe.problems));
  EXPECT_TRUE(any_contains(lathe.warnings, "m.ini: [JOINT_1] section missing"))
      << ::testing::PrintToString(strings(lathe.warnings));
}

TEST_F(WorkableConfigTest, JointsBeyondTheLastJointSectionAreRefused) {
  // JOINTS = 9 on a three-joint mill: six joints run on made-up defaults and homing never
  // completes. Whether the kinematics give them axes outside COORDINATES or none at all.
  const std::string expected =
      "[KINS] JOINTS: JOINTS = 9, but joints 3, 4, 5, 6, 7 and 8 have no [JOINT_n] section "
      "(the last is [JOINT_2]): set JOINTS = 3, or give each joint its section";
  EXPECT_EQ(problems_with(11, "JOINTS = 9"), problem_at(11, expected));
  EXPECT_EQ(problems_of(replace_line(
                replace_line(minimal_ini(), 10, "KINEMATICS = trivkins coordinates=XYZ"), 11,
                "JOINTS = 9")),
            problem_at(11, expected));
  // One joint too many: named alone.
  EXPECT_EQ(problems_with(11, "JOINTS = 4"),
            problem_at(11,
                       "[KINS] JOINTS: JOINTS = 4, but joint 3 has no [JOINT_n] section (the "
                       "last is [JOINT_2]): set JOINTS = 3, or give each joint its section"));
}

TEST_F(WorkableConfigTest, DefaultVelocityAboveTheMaximumIsLowered) {
  const auto result = load(
      replace_line(minimal_ini(), 7,
                   "LINEAR_UNITS = mm\nMAX_LINEAR_VELOCITY = 40\nDEFAULT_LINEAR_VELOCITY = 60"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->default_linear_velocity, 40);
  EXPECT_EQ(strings(result.warnings),
            std::vector<std::string>{at(9) + ": [TRAJ] DEFAULT_LINEAR_VELOCITY: 60 is above "
                                             "MAX_LINEAR_VELOCITY 40; lowered to it"});
}

TEST_F(WorkableConfigTest, RepeatedKeyWarnsWithBothLines) {
  const auto result = load(replace_line(minimal_ini(), 31,
                                        "MAX_ACCELERATION = 500\nMAX_VELOCITY = 20\n"
                                        "MAX_ACCELERATION = 500"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->joints[0].max_velocity, 50);  // the first, as LinuxCNC reads it
  EXPECT_EQ(strings(result.warnings),
            (std::vector<std::string>{
                at(32) + ": [JOINT_0] MAX_VELOCITY: given again with another value (20), which is "
                         "ignored: the first, at line 30 (50), is used",
                at(33) + ": [JOINT_0] MAX_ACCELERATION: given again; the first, at line 31, has "
                         "the same value"}));
}

TEST_F(WorkableConfigTest, RepeatedKeyInAnIncludeNamesTheOtherFile) {
  write("more.inc", "MAX_LINEAR_VELOCITY = 30\n");
  const auto result = load(replace_line(minimal_ini(), 7,
                                        "LINEAR_UNITS = mm\nMAX_LINEAR_VELOCITY = 40\n"
                                        "#INCLUDE more.inc"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(strings(result.warnings),
            std::vector<std::string>{TempDirTest::at("more.inc", 1) +
                                     ": [TRAJ] MAX_LINEAR_VELOCITY: given again with another "
                                     "value (30), which is ignored: the first, at " +
                                     at(8) + " (40), is used"});
}

TEST_F(WorkableConfigTest, KeysLinuxCncRepeatsOrCncdIgnoresAreNotReported) {
  const auto result =
      load(replace_line(minimal_ini(), 7, "LINEAR_UNITS = mm\nARC_BLEND_ENABLE = 1") +
           "[HAL]\nHALFILE = a.hal\nHALFILE = b.hal\n"
           "[RS274NGC]\nREMAP = M6 modalgroup=6\nREMAP = M61 modalgroup=6\n"
           "[FILTER]\nPROGRAM_EXTENSION = .py Python\nPROGRAM_EXTENSION = .png\n"
           "[DISPLAY]\nDISPLAY = axis\nEMBED_TAB_NAME = a\nEMBED_TAB_NAME = b\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
}

TEST_F(WorkableConfigTest, MisspeltKeyGetsTheClosestKnownOne) {
  const auto result = load(replace_line(minimal_ini(), 31,
                                        "MAX_ACCELERATION = 500\nMAX_VELOCTY = 20\n"
                                        "HOME_SEARCH_VELL = 5\nmin_ferror = 0.1\n"
                                        "MY_PID_GAIN = 3\nP = 100\nDEADBAND = 0.01"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  // Keys far from any known one may be read by HAL files ([JOINT_0]MY_PID_GAIN): no warning.
  EXPECT_EQ(strings(result.warnings),
            (std::vector<std::string>{
                at(32) + ": [JOINT_0] MAX_VELOCTY: unknown key, ignored; did you mean "
                         "MAX_VELOCITY?",
                at(33) + ": [JOINT_0] HOME_SEARCH_VELL: unknown key, ignored; did you mean "
                         "HOME_SEARCH_VEL?",
                at(34) + ": [JOINT_0] min_ferror: unknown key, ignored; did you mean MIN_FERROR? "
                         "(key names are case-sensitive)"}));
}

}  // namespace
}  // namespace cncd::config::test
