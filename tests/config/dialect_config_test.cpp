// [RS274NGC] DIALECT, NUMERYX_CLEARANCE and RIGID_TAPPING: read, defaulted, refused at their
// FILE:LINE, and shown in the --check-config summary.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

class DialectConfigTest : public MachineIniTest {
 protected:
  // What follows minimal_ini() starts at line 42.
  static constexpr int kFirst = 42;
  MachineConfig loaded(const std::string& extra) {
    const auto result = load(minimal_ini() + extra);
    EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
    EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
    return result.ok() ? *result.config : MachineConfig{};
  }
};

TEST_F(DialectConfigTest, KeysAreInTheTable) {
  const KeySpec* dialect = find_key_spec("RS274NGC", "DIALECT");
  ASSERT_NE(dialect, nullptr);
  EXPECT_EQ(dialect->type, KeyType::choice);
  EXPECT_EQ(dialect->default_value, "linuxcnc");
  EXPECT_EQ(dialect->choices, "linuxcnc|numeryx");
  const KeySpec* clearance = find_key_spec("RS274NGC", "NUMERYX_CLEARANCE");
  ASSERT_NE(clearance, nullptr);
  EXPECT_EQ(clearance->type, KeyType::real);
  EXPECT_EQ(clearance->default_value, "");
  EXPECT_EQ(clearance->unit, "units");
  EXPECT_TRUE(clearance->min_exclusive);
  EXPECT_EQ(clearance->min, 0);
}

TEST_F(DialectConfigTest, DefaultsToLinuxCncAndTheInterpretersClearance) {
  const MachineConfig c = loaded("");
  EXPECT_EQ(c.dialect, Dialect::linuxcnc);
  EXPECT_FALSE(c.numeryx_clearance.has_value());
  const std::string summary = describe(c);
  EXPECT_NE(summary.find("\nDialect:      linuxcnc (a program's first line \"(dialect NAME)\" "
                         "may name the other)\n"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("\nNumeryx clearance: 1 mm in G21 programs, 0.04 in in G20 ones\n"),
            std::string::npos)
      << summary;
}

TEST_F(DialectConfigTest, ReadsTheDialectInAnyCaseAndTheClearance) {
  const MachineConfig c =
      loaded("[RS274NGC]\nDIALECT = NumerYX\nNUMERYX_CLEARANCE = 0.5  # above R\n");
  EXPECT_EQ(c.dialect, Dialect::numeryx);
  ASSERT_TRUE(c.numeryx_clearance.has_value());
  EXPECT_EQ(*c.numeryx_clearance, 0.5);
  const std::string summary = describe(c);
  EXPECT_NE(summary.find("\nDialect:      numeryx ("), std::string::npos) << summary;
  EXPECT_NE(summary.find("\nNumeryx clearance: 0.5 mm\n"), std::string::npos) << summary;
  EXPECT_EQ(loaded("[RS274NGC]\nDIALECT = linuxcnc\n").dialect, Dialect::linuxcnc);
}

TEST_F(DialectConfigTest, ClearanceIsInMachineUnits) {
  const auto result = load(replace_line(minimal_ini(), 7, "LINEAR_UNITS = inch") +
                           "[RS274NGC]\nNUMERYX_CLEARANCE = 0.02\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(*result.config->numeryx_clearance, 0.02);
  EXPECT_NE(describe(*result.config).find("\nNumeryx clearance: 0.02 inch\n"), std::string::npos);
}

TEST_F(DialectConfigTest, UnknownDialectIsRefusedNamingTheAllowedOnes) {
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nDIALECT = fanuc\n"),
            problem_at(kFirst + 1,
                       "[RS274NGC] DIALECT: unknown value 'fanuc'; expected one of "
                       "linuxcnc, numeryx"));
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nDIALECT =\n"),
            problem_at(kFirst + 1,
                       "[RS274NGC] DIALECT: unknown value ''; expected one of "
                       "linuxcnc, numeryx"));
}

TEST_F(DialectConfigTest, ClearanceMustBeAPositiveNumber) {
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nNUMERYX_CLEARANCE = 0\n"),
            problem_at(kFirst + 1,
                       "[RS274NGC] NUMERYX_CLEARANCE: 0 is out of range: must be "
                       "greater than 0 units"));
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nNUMERYX_CLEARANCE = -1\n"),
            problem_at(kFirst + 1,
                       "[RS274NGC] NUMERYX_CLEARANCE: -1 is out of range: must be "
                       "greater than 0 units"));
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nNUMERYX_CLEARANCE = 1 mm\n"),
            problem_at(kFirst + 1, "[RS274NGC] NUMERYX_CLEARANCE: '1 mm' is not a number"));
}

TEST_F(DialectConfigTest, RigidTappingIsOffUnlessAsked) {
  const KeySpec* rigid = find_key_spec("RS274NGC", "RIGID_TAPPING");
  ASSERT_NE(rigid, nullptr);
  EXPECT_EQ(rigid->type, KeyType::boolean);
  EXPECT_EQ(rigid->default_value, "0");
  const MachineConfig floating = loaded("");
  EXPECT_FALSE(floating.rigid_tapping);
  EXPECT_NE(
      describe(floating).find("\nTapping:      G84/G74 with a floating holder, as LinuxCNC\n"),
      std::string::npos);
  const MachineConfig rigid_machine = loaded("[RS274NGC]\nRIGID_TAPPING = YES\n");
  EXPECT_TRUE(rigid_machine.rigid_tapping);
  EXPECT_NE(describe(rigid_machine)
                .find("\nTapping:      G84/G74 rigid, in step with the spindle ([RS274NGC] "
                      "RIGID_TAPPING)\n"),
            std::string::npos);
  EXPECT_EQ(problems_of(minimal_ini() + "[RS274NGC]\nRIGID_TAPPING = sometimes\n"),
            problem_at(kFirst + 1,
                       "[RS274NGC] RIGID_TAPPING: 'sometimes' is not a yes/no value (use 1/0, "
                       "YES/NO, TRUE/FALSE)"));
}

}  // namespace
}  // namespace cncd::config::test
