// Each bad configuration must be reported at its exact FILE:LINE, and all of them at once.
#include <gtest/gtest.h>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

using ValidationTest = MachineIniTest;

TEST_F(ValidationTest, MinimalIniIsValid) {
  const auto result = load_machine_config(write("m.ini", minimal_ini()));
  EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
}

TEST_F(ValidationTest, NonNumericNumber) {
  EXPECT_EQ(problems_with(30, "MAX_VELOCITY = fast"),
            problem_at(30, "[JOINT_0] MAX_VELOCITY: 'fast' is not a number"));
}

TEST_F(ValidationTest, TrailingCommentAfterNumberIsAcceptedButJunkIsNot) {
  const auto ok = load_machine_config(
      write("m.ini", replace_line(minimal_ini(), 30, "MAX_VELOCITY = 40   # mm/s")));
  ASSERT_TRUE(ok.ok()) << ::testing::PrintToString(strings(ok.problems));
  EXPECT_EQ(ok.config->joints[0].max_velocity, 40);
  EXPECT_EQ(problems_with(30, "MAX_VELOCITY = 40 mm/s"),
            problem_at(30, "[JOINT_0] MAX_VELOCITY: '40 mm/s' is not a number"));
}

TEST_F(ValidationTest, VelocitiesAndAccelerationsMustBePositive) {
  auto ini = replace_line(minimal_ini(), 15, "MAX_VELOCITY = -5");
  ini = replace_line(ini, 31, "MAX_ACCELERATION = 0");
  EXPECT_EQ(
      problems_of(ini),
      (std::vector<std::string>{
          at(15) + ": [AXIS_X] MAX_VELOCITY: -5 is out of range: must be greater than 0 units/s",
          at(31) + ": [JOINT_0] MAX_ACCELERATION: 0 is out of range: must be greater than 0 "
                   "units/s^2"}));
}

TEST_F(ValidationTest, EqualLimitsAreOnlyAWarning) {
  auto ini = replace_line(minimal_ini(), 13, "MIN_LIMIT = 100");
  ini = replace_line(ini, 28, "MIN_LIMIT = -10");
  const auto result = load_machine_config(write("m.ini", ini));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(any_contains(result.warnings,
                           at(14) + ": [AXIS_X] MAX_LIMIT: MIN_LIMIT equals MAX_LIMIT (100)"));
}

TEST_F(ValidationTest, MinLimitMustBeBelowMaxLimit) {
  auto ini = replace_line(minimal_ini(), 13, "MIN_LIMIT = 200");
  ini = replace_line(ini, 28, "MIN_LIMIT = 200");
  EXPECT_EQ(problems_of(ini),
            (std::vector<std::string>{
                at(14) + ": [AXIS_X] MAX_LIMIT: MIN_LIMIT 200 must be below MAX_LIMIT 100",
                at(29) + ": [JOINT_0] MAX_LIMIT: MIN_LIMIT 200 must be below MAX_LIMIT 100"}));
}

TEST_F(ValidationTest, JointLimitsMustIncludeAxisLimits) {
  auto ini = replace_line(minimal_ini(), 28, "MIN_LIMIT = -5");
  ini = replace_line(ini, 29, "MAX_LIMIT = 90");
  EXPECT_EQ(problems_of(ini),
            (std::vector<std::string>{
                at(28) + ": [JOINT_0] MIN_LIMIT: -5 is narrower than [AXIS_X] MIN_LIMIT -10; joint "
                         "limits must include the axis limits",
                at(29) + ": [JOINT_0] MAX_LIMIT: 90 is narrower than [AXIS_X] MAX_LIMIT 100; joint "
                         "limits must include the axis limits"}));
}

TEST_F(ValidationTest, ServoAndBasePeriods) {
  EXPECT_EQ(
      problems_with(4, "SERVO_PERIOD = 10000"),
      problem_at(
          4,
          "[EMCMOT] SERVO_PERIOD: 10000 is out of range: must be between 50000 and 100000000 ns"));
  EXPECT_EQ(
      problems_with(4, "SERVO_PERIOD = 1000000\nBASE_PERIOD = 2000000"),
      problem_at(
          5, "[EMCMOT] BASE_PERIOD: 2000000 ns must not be longer than SERVO_PERIOD 1000000 ns"));
  const auto equal = load_machine_config(write(
      "eq.ini", replace_line(minimal_ini(), 4, "SERVO_PERIOD = 1000000\nBASE_PERIOD = 1000000")));
  EXPECT_TRUE(equal.ok()) << ::testing::PrintToString(strings(equal.problems));
  EXPECT_EQ(problems_with(4, "SERVO_PERIOD = 1000000.5"),
            problem_at(4, "[EMCMOT] SERVO_PERIOD: '1000000.5' is not a whole number"));
}

TEST_F(ValidationTest, UnknownUnits) {
  EXPECT_EQ(problems_with(7, "LINEAR_UNITS = furlong"),
            problem_at(7,
                       "[TRAJ] LINEAR_UNITS: unknown value 'furlong'; expected one of mm, metric, "
                       "inch, in, imperial"));
}

TEST_F(ValidationTest, JointsMustMatchCoordinates) {
  EXPECT_EQ(problems_of(replace_line(replace_line(minimal_ini(), 6, "COORDINATES = X Y Y Z"), 11,
                                     "JOINTS = 2")),
            std::vector<std::string>{at(11) + ": [KINS] JOINTS: JOINTS = 2 does not match "
                                              "COORDINATES XYYZ, which names 4 joints"});
  EXPECT_EQ(
      problems_with(10, "KINEMATICS = trivkins coordinates=XYYZ"),
      problem_at(11,
                 "[KINS] JOINTS: JOINTS = 3 is too few: trivkins coordinates=XYYZ needs 4 joints"));
  EXPECT_EQ(
      problems_with(11, "JOINTS = 2"),
      problem_at(11, "[KINS] JOINTS: JOINTS = 2 is too few for the 3 axes of COORDINATES XYZ"));
}

TEST_F(ValidationTest, JointSectionNames) {
  EXPECT_EQ(problems_of(minimal_ini() + "[JOINT_1]\nMAX_VELOCITY = 5\n"),
            std::vector<std::string>{at(42) + ": [JOINT_1] duplicate section; the first is at " +
                                     at(32)});
  // LinuxCNC ignores a [JOINT_n] beyond JOINTS, and shipped configs have them: a warning.
  const auto spare = load_machine_config(write("m.ini", minimal_ini() + "[JOINT_3]\n"));
  ASSERT_TRUE(spare.ok());
  EXPECT_EQ(strings(spare.warnings),
            std::vector<std::string>{at(42) + ": [JOINT_3] joint index out of range: [KINS] JOINTS "
                                              "= 3, so joints are 0 .. 2; section ignored"});
  EXPECT_EQ(problems_of(minimal_ini() + "[JOINT_16]\n"),
            std::vector<std::string>{at(42) + ": [JOINT_16] joint index out of range; joints are "
                                              "numbered 0 .. 15"});
  EXPECT_EQ(problems_of(minimal_ini() + "[JOINT_x]\n"),
            std::vector<std::string>{at(42) + ": [JOINT_x] not a joint section; joints are "
                                              "[JOINT_0] .. [JOINT_15]"});
}

TEST_F(ValidationTest, AxisSectionNames) {
  EXPECT_EQ(problems_of(minimal_ini() + "[AXIS_x]\n"),
            std::vector<std::string>{at(42) + ": [AXIS_x] section names are case-sensitive: "
                                              "LinuxCNC ignores [AXIS_x], write [AXIS_X]"});
  EXPECT_EQ(
      problems_of(minimal_ini() + "[AXIS_Y]\nMAX_VELOCITY = 3\n"),
      std::vector<std::string>{at(42) + ": [AXIS_Y] duplicate section; the first is at " + at(17)});
}

TEST_F(ValidationTest, LegacyNumberedAxes) {
  EXPECT_EQ(problems_of("[TRAJ]\nCOORDINATES = X Y Z\n[AXIS_0]\nMAX_VELOCITY = 1\n[AXIS_1]\n"),
            std::vector<std::string>{
                at(3) + ": [AXIS_0] LinuxCNC 2.7-style configuration (numbered [AXIS_n] sections, "
                        "no [JOINT_n]); convert it with LinuxCNC's update_ini to [JOINT_n] and "
                        "[AXIS_<letter>] sections"});
}

TEST_F(ValidationTest, UnknownDriver) {
  EXPECT_EQ(
      problems_of(minimal_ini("DRIVER = ethercat\n")),
      (std::vector<std::string>{
          at(32) +
              ": [JOINT_0] DRIVER: unknown value 'ethercat'; expected one of sim, gpio, modbus",
          at(38) +
              ": [JOINT_1] DRIVER: unknown value 'ethercat'; expected one of sim, gpio, modbus",
          at(44) +
              ": [JOINT_2] DRIVER: unknown value 'ethercat'; expected one of sim, gpio, modbus"}));
  // Names are case-insensitive, as LinuxCNC's values are.
  const auto ok = load_machine_config(write("ok.ini", minimal_ini("DRIVER = Sim\n")));
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.config->joints[2].driver, "sim");
  // A step/dir joint without its lines, scale, base thread and chip cannot run: refused.
  const auto gpio = load_machine_config(write("gpio.ini", minimal_ini("DRIVER = GPIO\n")));
  EXPECT_FALSE(gpio.ok());
  EXPECT_FALSE(gpio.problems.empty());
}

TEST_F(ValidationTest, UnsupportedKinematics) {
  EXPECT_EQ(problems_with(10, "KINEMATICS = pumakins"),
            problem_at(10,
                       "[KINS] KINEMATICS: kinematics 'pumakins' is not supported; cncd supports "
                       "trivkins, corexykins, xyzac-trt-kins and xyzbc-trt-kins"));
}

TEST_F(ValidationTest, DisplayOverrideLimitsAreRead) {
  const auto result = load_machine_config(write(
      "m.ini", minimal_ini() + "[DISPLAY]\nMAX_FEED_OVERRIDE = 1.2\nMIN_SPINDLE_OVERRIDE = 0.5\n"
                               "MAX_SPINDLE_OVERRIDE = 1.5\n"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->max_feed_override, 1.2);
  EXPECT_EQ(result.config->min_spindle_override, 0.5);
  EXPECT_EQ(result.config->max_spindle_override, 1.5);
  const auto defaults = load_machine_config(write("d.ini", minimal_ini()));
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults.config->max_feed_override, 1.0);
  EXPECT_EQ(defaults.config->min_spindle_override, 1.0);
  EXPECT_EQ(defaults.config->max_spindle_override, 1.0);
}

TEST_F(ValidationTest, SpindleOverrideRangeMustNotBeInverted) {
  // Lines 42.. are the appended [DISPLAY] section.
  EXPECT_EQ(problems_of(minimal_ini() +
                        "[DISPLAY]\nMIN_SPINDLE_OVERRIDE = 1.2\nMAX_SPINDLE_OVERRIDE = 0.8\n"),
            std::vector<std::string>{at(43) +
                                     ": [DISPLAY] MIN_SPINDLE_OVERRIDE: MIN_SPINDLE_OVERRIDE 1.2 "
                                     "must not be above MAX_SPINDLE_OVERRIDE 0.8"});
  EXPECT_EQ(problems_of(minimal_ini() + "[DISPLAY]\nMAX_SPINDLE_OVERRIDE = 0.8\n"),
            std::vector<std::string>{at(43) +
                                     ": [DISPLAY] MAX_SPINDLE_OVERRIDE: MIN_SPINDLE_OVERRIDE 1 "
                                     "(the default) must not be above MAX_SPINDLE_OVERRIDE 0.8"});
  EXPECT_EQ(problems_of(minimal_ini() + "[DISPLAY]\nMAX_SPINDLE_OVERRIDE = -1\n"),
            std::vector<std::string>{at(43) +
                                     ": [DISPLAY] MAX_SPINDLE_OVERRIDE: -1 is out of range: must "
                                     "be between 0 and 10 ratio"});
}

TEST_F(ValidationTest, MissingKinsKeys) {
  EXPECT_EQ(
      problems_of(replace_line(replace_line(minimal_ini(), 10, ""), 11, "")),
      (std::vector<std::string>{at(9) + ": [KINS] KINEMATICS: missing; write KINEMATICS = trivkins",
                                at(9) + ": [KINS] JOINTS: missing; the number of joints"}));
}

TEST_F(ValidationTest, BadCoordinateLetter) {
  EXPECT_EQ(problems_with(6, "COORDINATES = X Q Z"),
            problem_at(6, "[TRAJ] COORDINATES: 'X Q Z': 'Q' is not an axis letter (XYZABCUVW)"));
}

TEST_F(ValidationTest, RepeatedSectionThatSaysSomethingElse) {
  EXPECT_EQ(problems_of(minimal_ini() +
                        "[KINS]\nJOINTS = 3\nKINEMATICS = trivkins\n[KINS]\nJOINTS = 4\n"),
            std::vector<std::string>{at(46) +
                                     ": [KINS] JOINTS: ignored: [KINS] appears again here, "
                                     "and only the first one (" +
                                     at(9) + ") is read"});
  const auto same = load_machine_config(
      write("same.ini", minimal_ini() + "[KINS]\nJOINTS = 3\nKINEMATICS = trivkins\n"));
  EXPECT_TRUE(same.ok()) << ::testing::PrintToString(strings(same.problems));
}

TEST_F(ValidationTest, UnknownKeyInCncdSection) {
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nSOCKT = /tmp/x\n"),
            std::vector<std::string>{at(43) + ": [CNCD] SOCKT: unknown key in cncd's own section; "
                                              "did you mean SOCKET?"});
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nSPEED = 3\n"),
            std::vector<std::string>{at(43) + ": [CNCD] SPEED: unknown key in cncd's own section"});
}

TEST_F(ValidationTest, AllProblemsAreCollected) {
  auto ini = replace_line(minimal_ini(), 4, "SERVO_PERIOD = 1");
  ini = replace_line(ini, 7, "LINEAR_UNITS = cubits");
  ini = replace_line(ini, 15, "MAX_VELOCITY = fast");
  ini = replace_line(ini, 30, "MAX_VELOCITY = -1");
  ini += "[JOINT_99]\n[]\n";
  const auto problems = problems_of(ini);
  ASSERT_EQ(problems.size(), 6u) << ::testing::PrintToString(problems);
  EXPECT_EQ(problems[0].substr(0, at(4).size()), at(4));
  EXPECT_EQ(problems[1].substr(0, at(7).size()), at(7));
  EXPECT_EQ(problems[2].substr(0, at(15).size()), at(15));
  EXPECT_EQ(problems[3].substr(0, at(30).size()), at(30));
  EXPECT_EQ(problems[4].substr(0, at(42).size()), at(42));
  EXPECT_EQ(problems[5].substr(0, at(43).size()), at(43));
}

// [TRAJ] MAX_LINEAR_JERK asks for S-curve profiles; LinuxCNC's PLANNER_TYPE = 0 keeps
// trapezoids and PLANNER_TYPE = 1 needs a jerk of at least 1, both with a warning otherwise.
TEST_F(ValidationTest, JerkLimitAndPlannerType) {
  auto load = [&](const std::string& lines) {
    return load_machine_config(
        write("m.ini", replace_line(minimal_ini(), 7, "LINEAR_UNITS = mm\n" + lines)));
  };
  // Whether each combination plans S-curve profiles, and the warnings it gives.
  const struct {
    const char* lines;
    bool scurve;
    std::vector<std::string> warnings;
  } cases[] = {
      {"", false, {}},
      {"MAX_LINEAR_JERK = 50000", true, {}},
      {"PLANNER_TYPE = 1\nMAX_LINEAR_JERK = 50000", true, {}},
      {"PLANNER_TYPE = 0\nMAX_LINEAR_JERK = 50000", false, {"MAX_LINEAR_JERK is not applied"}},
      {"PLANNER_TYPE = 1\nMAX_LINEAR_JERK = 0.5", false, {"needs MAX_LINEAR_JERK >= 1"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.lines);
    const auto result = load(c.lines);
    ASSERT_TRUE(result.ok());
    EXPECT_EQ(result.config->scurve, c.scurve);
    const auto warnings = strings(result.warnings);
    ASSERT_EQ(warnings.size(), c.warnings.size());
    for (std::size_t k = 0; k < warnings.size(); ++k)
      EXPECT_NE(warnings[k].find(c.warnings[k]), std::string::npos) << warnings[k];
  }
  EXPECT_EQ(load("MAX_LINEAR_JERK = 50000").config->max_linear_jerk, 50000);
  EXPECT_EQ(
      strings(load("PLANNER_TYPE = 1\nMAX_LINEAR_JERK = 0.5").warnings),
      std::vector<std::string>{
          at(8) + ": [TRAJ] PLANNER_TYPE: PLANNER_TYPE = 1 (S-curve) needs MAX_LINEAR_JERK >= 1 "
                  "(got 0.5): planning trapezoidal profiles"});
  EXPECT_EQ(problems_with(7, "LINEAR_UNITS = mm\nPLANNER_TYPE = 2"),
            problem_at(8, "[TRAJ] PLANNER_TYPE: 2 is out of range: must be between 0 and 1"));
}

}  // namespace
}  // namespace cncd::config::test
