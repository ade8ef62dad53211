#include "cncd/config/machine_config.hpp"

#include <gtest/gtest.h>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/ini_file.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

const std::filesystem::path kExamples = CNCD_CONFIG_EXAMPLES_DIR;

TEST(AxisIndexTest, MapsLettersInLinuxCncOrder) {
  EXPECT_EQ(axis_index('X'), 0);
  EXPECT_EQ(axis_index('z'), 2);
  EXPECT_EQ(axis_index('W'), 8);
  EXPECT_EQ(axis_index('Q'), -1);
  EXPECT_EQ(axis_index('\0'), -1);
}

TEST(ProblemTest, PrintsFileLineSectionKeyMessage) {
  EXPECT_EQ((Problem{"m.ini", 12, "JOINT_0", "MAX_VELOCITY", "bad"}).to_string(),
            "m.ini:12: [JOINT_0] MAX_VELOCITY: bad");
  EXPECT_EQ((Problem{"m.ini", 0, "", "", "cannot open"}).to_string(), "m.ini: cannot open");
  EXPECT_EQ((Problem{"m.ini", 3, "KINS", "", "x"}).to_string(), "m.ini:3: [KINS] x");
}

TEST(KeyTableTest, EveryKeyHasHelpAndSaneRange) {
  for (const auto& spec : key_table()) {
    EXPECT_FALSE(spec.help.empty()) << spec.section << " " << spec.key;
    EXPECT_LE(spec.min, spec.max) << spec.key;
    if (spec.type == KeyType::choice) {
      EXPECT_FALSE(spec.choices.empty()) << spec.key;
    }
  }
  ASSERT_NE(find_key_spec("JOINT_7", "MAX_VELOCITY"), nullptr);
  EXPECT_EQ(find_key_spec("AXIS_B", "MAX_LIMIT")->section, "AXIS_L");
  EXPECT_EQ(find_key_spec("HAL", "HALFILE"), nullptr);
}

TEST(ExampleConfigTest, SimMmLoadsWithoutProblemsOrWarnings) {
  const auto result = load_machine_config(kExamples / "sim_mm.ini");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
  const MachineConfig& c = *result.config;
  EXPECT_EQ(c.linear_units, LinearUnits::mm);
  EXPECT_EQ(c.servo_period_ns, 1'000'000);
  EXPECT_EQ(c.coordinates, "XYZ");
  EXPECT_EQ(c.joint_count, 3);
  ASSERT_EQ(c.joints.size(), 3u);
  EXPECT_EQ(c.max_linear_velocity, 250);
  // The state files live in the state directory, starting from the example's own copies.
  EXPECT_FALSE(c.cncd.state_dir.empty());
  EXPECT_EQ(c.parameter_file, c.cncd.state_dir / "sim_mm.var");
  EXPECT_EQ(c.tool_table, c.cncd.state_dir / "sim_mm.tbl");
  EXPECT_EQ(c.position_file, c.cncd.state_dir / "sim_mm.position");
  EXPECT_EQ(c.parameter_file_seed, (kExamples / "sim_mm.var").lexically_normal());
  EXPECT_EQ(c.tool_table_seed, (kExamples / "sim_mm.tbl").lexically_normal());
  EXPECT_TRUE(std::filesystem::exists(c.parameter_file_seed));
  EXPECT_TRUE(std::filesystem::exists(c.tool_table_seed));
  EXPECT_EQ(c.cncd.socket_path, "/run/cncd/cncd.sock");
  EXPECT_EQ(c.cncd.log_level, "info");
  for (const auto& j : c.joints) {
    EXPECT_EQ(j.driver, "sim");
    EXPECT_EQ(j.home, 0);
    EXPECT_EQ(j.home_search_vel, 0);
  }
  // The demo program: G0 X1 Y2 Z3, then G81 at X4 Y5 with Z1.5 R2.8 (mm).
  for (const auto& [letter, position] : std::vector<std::pair<char, double>>{
           {'X', 1}, {'Y', 2}, {'Z', 3}, {'X', 4}, {'Y', 5}, {'Z', 1.5}, {'Z', 2.8}}) {
    EXPECT_GE(position, c.axis(letter).min_limit) << letter;
    EXPECT_LE(position, c.axis(letter).max_limit) << letter;
  }
  EXPECT_EQ(c.axis('X').max_velocity, 200);
  EXPECT_EQ(c.axis('Z').max_velocity, 100);
  EXPECT_EQ(c.axis('Z').max_acceleration, 1000);
  EXPECT_EQ(c.axis('Y').min_limit, -10);
  EXPECT_EQ(c.axis('Y').max_limit, 200);
  EXPECT_FALSE(c.axis('A').present);
  ASSERT_NE(c.ini, nullptr);
  EXPECT_EQ(c.ini->value("EMC", "MACHINE"), c.machine_name);
}

TEST(ExampleConfigTest, SimInchIsTheSameMachineInInches) {
  const auto mm = load_machine_config(kExamples / "sim_mm.ini");
  const auto inch = load_machine_config(kExamples / "sim_inch.ini");
  ASSERT_TRUE(mm.ok() && inch.ok()) << ::testing::PrintToString(strings(inch.problems));
  EXPECT_TRUE(inch.warnings.empty()) << ::testing::PrintToString(strings(inch.warnings));
  EXPECT_EQ(inch.config->linear_units, LinearUnits::inch);
  EXPECT_DOUBLE_EQ(inch.config->mm_per_unit(), 25.4);
  for (const char letter : std::string("XYZ")) {
    const auto& a = mm.config->axis(letter);
    const auto& b = inch.config->axis(letter);
    EXPECT_NEAR(b.max_limit * 25.4, a.max_limit, 0.05 * std::abs(a.max_limit)) << letter;
    EXPECT_NEAR(b.min_limit * 25.4, a.min_limit, 0.05 * std::abs(a.min_limit)) << letter;
    EXPECT_NEAR(b.max_velocity * 25.4, a.max_velocity, 0.05 * a.max_velocity) << letter;
    EXPECT_NEAR(b.max_acceleration * 25.4, a.max_acceleration, 0.05 * a.max_acceleration);
  }
}

TEST(DescribeTest, SummarisesTheMachine) {
  const auto result = load_machine_config(kExamples / "sim_mm.ini");
  ASSERT_TRUE(result.ok());
  const std::string text = describe(*result.config);
  for (const std::string expected :
       {"Machine:      cncd sim mill (mm)", "sim_mm.ini", "Units:        linear mm, angular degree",
        "Servo period: 1000000 ns (1000 Hz)", "Base period:  none",
        "Kinematics:   trivkins coordinates=XYZ", "Coordinates:  XYZ (3 joints)",
        "  X: limits -10 .. 300 mm, max velocity 200 mm/s, max acceleration 2000 mm/s^2",
        "  Z: limits -100 .. 50 mm, max velocity 100 mm/s, max acceleration 1000 mm/s^2",
        "  2: axis Z, linear, driver sim",
        "     limits -100 .. 50 mm, max velocity 100 mm/s, max acceleration 1000 mm/s^2",
        "ferror 1 (standstill 0.25) mm", "home 0 mm, homes where it stands, sequence 0",
        "socket /run/cncd/cncd.sock", "RT priority 80, RT CPU any, log level info",
        "connections at most 1000, 128 per user, the last 8 kept for control access"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << "missing: " << expected << "\n" << text;
  }
}

using LoaderTest = TempDirTest;

TEST_F(LoaderTest, GantryFromKinematicsCoordinates) {
  std::string ini = minimal_ini();
  ini.replace(ini.find("COORDINATES = X Y Z"), 19, "COORDINATES = X Y Y Z");
  ini.replace(ini.find("KINEMATICS = trivkins\nJOINTS = 3"), 32,
              "KINEMATICS = trivkins coordinates=XYYZ kinstype=BOTH\nJOINTS = 4");
  ini +=
      "[JOINT_3]\nMIN_LIMIT = -10\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n"
      "HOME_SEQUENCE = -1\n";
  const auto result = load_machine_config(write("g.ini", ini));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const auto& c = *result.config;
  EXPECT_EQ(c.coordinates, "XYYZ");
  EXPECT_EQ(c.kinematics, "trivkins");
  EXPECT_EQ(c.kinematics_args, "coordinates=XYYZ kinstype=BOTH");
  ASSERT_EQ(c.joints.size(), 4u);
  EXPECT_EQ(std::string({c.joints[0].axis, c.joints[1].axis, c.joints[2].axis, c.joints[3].axis}),
            "XYYZ");
  EXPECT_EQ(c.joints[3].home_sequence, 1);
  EXPECT_TRUE(c.joints[3].home_sequence_sync);
}

TEST_F(LoaderTest, GantryWrittenOnlyInTrajCoordinates) {
  std::string ini = minimal_ini();
  ini.replace(ini.find("COORDINATES = X Y Z"), 19, "COORDINATES = XYYZ");
  ini.replace(ini.find("JOINTS = 3"), 10, "JOINTS = 4");
  ini += "[JOINT_3]\nMIN_LIMIT = -10\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n";
  const auto result = load_machine_config(write("g.ini", ini));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->joints[2].axis, 'Y');
  EXPECT_EQ(result.config->joints[3].axis, 'Z');
}

TEST_F(LoaderTest, DefaultsFollowLinuxCnc) {
  const auto result = load_machine_config(
      write("d.ini",
            "[TRAJ]\nCOORDINATES = X Z\nLINEAR_UNITS = 0.03937007874\nANGULAR_UNITS = deg\n"
            "[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n[AXIS_X]\nMIN_LIMIT = -5\nMAX_LIMIT = 5\n"
            "[AXIS_Z]\nMAX_VELOCITY = 2\nMAX_ACCELERATION = 20\n[JOINT_0]\nFERROR = 0.5\n"
            "[JOINT_2]\nMAX_VELOCITY = 2\nMAX_ACCELERATION = 20\n[HAL]\nHALFILE = x.hal\n"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const auto& c = *result.config;
  EXPECT_EQ(c.linear_units, LinearUnits::inch);
  EXPECT_EQ(c.servo_period_ns, 1'000'000);
  EXPECT_EQ(c.joints[1].axis, 'Y');  // trivkins without coordinates=: joint n is axis n
  EXPECT_EQ(c.joints[2].axis, 'Z');
  EXPECT_EQ(c.joints[0].min_limit, -5);  // from [AXIS_X]
  EXPECT_EQ(c.joints[0].max_velocity, 1.0);
  EXPECT_EQ(c.joints[0].min_ferror, 0.5);  // MIN_FERROR defaults to FERROR
  EXPECT_EQ(c.joints[0].home_sequence, -1);
  EXPECT_EQ(c.axis('X').max_velocity, 1.0);
  EXPECT_EQ(c.axis('Z').min_limit, -1e99);
  EXPECT_EQ(c.max_linear_velocity, 2);  // the fastest linear axis
  EXPECT_TRUE(any_contains(result.warnings, "[AXIS_X] MAX_VELOCITY: not given"));
  EXPECT_TRUE(any_contains(result.warnings, "[JOINT_1] section missing"));
  ASSERT_NE(c.ini, nullptr);
  const auto unused = c.ini->unused_entries();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0]->key, "HALFILE");
}

TEST_F(LoaderTest, CncdSectionAndRelativePaths) {
  const auto result = load_machine_config(write(
      "sub/c.ini", minimal_ini() +
                       "[CNCD]\nSOCKET = run/c.sock\nREAD_GROUP = viewers\nCONTROL_GROUP = ops\n"
                       "RT_PRIORITY = 60\nRT_CPU = 1\nLOG_LEVEL = Warning\n"
                       "[RS274NGC]\nSUBROUTINE_PATH = subs:../lib/subs: /abs\n"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const auto& c = *result.config;
  EXPECT_EQ(c.cncd.socket_path, (dir_ / "sub/run/c.sock").string());
  EXPECT_EQ(c.cncd.read_group, "viewers");
  EXPECT_EQ(c.cncd.control_group, "ops");
  EXPECT_EQ(c.cncd.rt_priority, 60);
  EXPECT_EQ(c.cncd.rt_cpu, 1);
  EXPECT_EQ(c.cncd.log_level, "warn");
  ASSERT_EQ(c.subroutine_path.size(), 3u);
  EXPECT_EQ(c.subroutine_path[0], dir_ / "sub/subs");
  EXPECT_EQ(c.subroutine_path[1], dir_ / "lib/subs");
  EXPECT_EQ(c.subroutine_path[2], "/abs");
}

}  // namespace
}  // namespace cncd::config::test
