// The line keys of [GPIO] and of step/dir joints (ESTOP_LINE, HOME_SWITCH_LINE, STEP_LINE ...):
// a bare line as before, or a gpio: address as every other input takes, with '!' for the
// key's *_ACTIVE_LOW; what they cannot take refused at its FILE:LINE.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "cncd/config/ini_file.hpp"
#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

GpioLineKey read(std::string_view key, std::string_view value,
                 std::optional<bool> active_low = std::nullopt) {
  GpioLineKey out;
  const std::string error = parse_gpio_line_key(key, value, active_low, out);
  EXPECT_EQ(error, "") << key << " = " << value;
  return out;
}

std::string refusal(std::string_view key, std::string_view value,
                    std::optional<bool> active_low = std::nullopt) {
  GpioLineKey out{"untouched", true};
  const std::string error = parse_gpio_line_key(key, value, active_low, out);
  EXPECT_EQ(out.line, "untouched") << "a refused value leaves the output alone: " << value;
  return error;
}

TEST(GpioLineKeyTest, BareLineAndAddressFormReadTheSame) {
  for (const char* value : {"GPIO4", "gpio:GPIO4", " GPIO:GPIO4 "}) {
    EXPECT_EQ(read("ESTOP_LINE", value).line, "GPIO4") << value;
    EXPECT_FALSE(read("ESTOP_LINE", value).active_low) << value;
    EXPECT_TRUE(read("ESTOP_LINE", value, true).active_low) << value;
    EXPECT_FALSE(read("ESTOP_LINE", value, false).active_low) << value;
  }
  EXPECT_EQ(read("STEP_LINE", "17").line, "17");
  EXPECT_EQ(read("STEP_LINE", "gpio:17").line, "17");
  // A trailing comment is no part of the line, for the driver as for validation.
  EXPECT_EQ(read("DIR_LINE", "GPIO27   # high = negative").line, "GPIO27");
  EXPECT_TRUE(read("ENABLE_LINE", "gpio:!22 ; ENA-").active_low);
  // Empty: not connected, as before.
  EXPECT_EQ(read("PROBE_LINE", "").line, "");
  EXPECT_EQ(read("PROBE_LINE", "  ").line, "");
  // A bare value is the line exactly as today, even a name no gpio: address could spell.
  EXPECT_EQ(read("HOME_SWITCH_LINE", "P8_03 [mmc1]").line, "P8_03 [mmc1]");
}

TEST(GpioLineKeyTest, BangIsTheKeysActiveLow) {
  for (const char* key : {"ESTOP_LINE", "PROBE_LINE", "HOME_SWITCH_LINE", "MIN_LIMIT_LINE",
                          "MAX_LIMIT_LINE", "ENABLE_LINE"}) {
    const GpioLineKey k = read(key, "gpio:!GPIO4");
    EXPECT_EQ(k.line, "GPIO4") << key;
    EXPECT_TRUE(k.active_low) << key;
  }
  EXPECT_EQ(line_active_low_key("ESTOP_LINE"), "ESTOP_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("PROBE_LINE"), "PROBE_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("HOME_SWITCH_LINE"), "HOME_SWITCH_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("MIN_LIMIT_LINE"), "MIN_LIMIT_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("MAX_LIMIT_LINE"), "MAX_LIMIT_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("ENABLE_LINE"), "ENABLE_ACTIVE_LOW");
  EXPECT_EQ(line_active_low_key("STEP_LINE"), "");
  EXPECT_EQ(line_active_low_key("DIR_LINE"), "");
}

TEST(GpioLineKeyTest, PolarityIsGivenOnce) {
  EXPECT_EQ(refusal("ESTOP_LINE", "gpio:!GPIO4", true),
            "'gpio:!GPIO4': active low is given twice, by '!' and by ESTOP_ACTIVE_LOW = 1: "
            "give it once");
  EXPECT_EQ(refusal("MIN_LIMIT_LINE", "gpio:!3", false),
            "'gpio:!3': '!' makes the line active low, but MIN_LIMIT_ACTIVE_LOW = 0 says it is "
            "not: give the polarity once, by '!' or by MIN_LIMIT_ACTIVE_LOW");
}

TEST(GpioLineKeyTest, StepAndDirectionLinesTakeNoBang) {
  EXPECT_EQ(refusal("STEP_LINE", "gpio:!17"),
            "'gpio:!17': STEP_LINE takes no '!': there is no STEP_ACTIVE_LOW");
  EXPECT_EQ(refusal("DIR_LINE", "gpio:!GPIO27"),
            "'gpio:!GPIO27': DIR_LINE takes no '!': there is no DIR_ACTIVE_LOW (a negative "
            "SCALE reverses the direction)");
}

TEST(GpioLineKeyTest, OnlyGpioLinesAreTaken) {
  EXPECT_EQ(refusal("ESTOP_LINE", "sim:estop"),
            "'sim:estop': this input is read in the gpio driver's base thread, so it takes only "
            "a gpio line (LINE, gpio:LINE or gpio:!LINE)");
  EXPECT_EQ(refusal("HOME_SWITCH_LINE", "modbus:0:1:di:4"),
            "'modbus:0:1:di:4': this input is read in the gpio driver's base thread, so it "
            "takes only a gpio line (LINE, gpio:LINE or gpio:!LINE)");
  EXPECT_EQ(refusal("PROBE_LINE", "sim:probe"),
            "'sim:probe': this input is read in the gpio driver's base thread, so it takes only "
            "a gpio line (LINE, gpio:LINE or gpio:!LINE); [CNCD] PROBE_INPUT takes a gpio: or "
            "sim: probe");
  EXPECT_EQ(refusal("MAX_LIMIT_LINE", "evdev:/dev/input/event3:KEY_A"),
            "'evdev:/dev/input/event3:KEY_A': this input is read in the gpio driver's base "
            "thread, so it takes only a gpio line (LINE, gpio:LINE or gpio:!LINE)");
  EXPECT_EQ(refusal("STEP_LINE", "sim:step"),
            "'sim:step': this output is driven in the gpio driver's base thread, so it takes "
            "only a gpio line (LINE or gpio:LINE)");
  EXPECT_EQ(refusal("ENABLE_LINE", "modbus:0:1:coil:2"),
            "'modbus:0:1:coil:2': this output is driven in the gpio driver's base thread, so it "
            "takes only a gpio line (LINE, gpio:LINE or gpio:!LINE)");
  // A malformed address says what is wrong with it.
  EXPECT_EQ(refusal("ESTOP_LINE", "gpio:"), "'gpio:': empty line");
  EXPECT_EQ(refusal("ESTOP_LINE", "sim:"), "'sim:': empty signal name");
}

// The keys as load_machine_config reads them: joint 2 (the last section of gpio_ini()) steps
// on gpio lines, so that what is appended goes into [JOINT_2] first.
class GpioLineKeysLoadTest : public IoConfigTest {
 protected:
  static std::string gpio_joint(const std::string& keys) {
    return gpio_ini("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = 1\nDIR_LINE = 2\n" + keys + chip());
  }
};

TEST_F(GpioLineKeysLoadTest, BothFormsLoad) {
  loaded(gpio_ini(chip() + "ESTOP_LINE = gpio:!GPIO4\nPROBE_LINE = gpio:GPIO18\n"));
  loaded(gpio_ini(chip() + "ESTOP_LINE = GPIO4\nESTOP_ACTIVE_LOW = 1\nPROBE_LINE = 18\n"));
  loaded(
      gpio_joint("ENABLE_LINE = gpio:!3\nHOME_SWITCH_LINE = gpio:!GPIO5\n"
                 "MIN_LIMIT_LINE = gpio:6\nMAX_LIMIT_LINE = 7\nMAX_LIMIT_ACTIVE_LOW = 1\n"));
  loaded(
      gpio_ini("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = gpio:1\nDIR_LINE = GPIO:GPIO2\n" + chip()));
}

TEST_F(GpioLineKeysLoadTest, RefusalsNameFileLineKeyAndReason) {
  EXPECT_EQ(problems_of(gpio_ini(chip() + "ESTOP_LINE = gpio:!GPIO4\nESTOP_ACTIVE_LOW = 1\n")),
            problem_at(kFirst + 2,
                       "[GPIO] ESTOP_LINE: 'gpio:!GPIO4': active low is given twice, by '!' and "
                       "by ESTOP_ACTIVE_LOW = 1: give it once"));
  EXPECT_EQ(problems_of(gpio_ini(chip() + "ESTOP_LINE = sim:estop\n")),
            problem_at(kFirst + 2,
                       "[GPIO] ESTOP_LINE: 'sim:estop': this input is read in the gpio driver's "
                       "base thread, so it takes only a gpio line (LINE, gpio:LINE or "
                       "gpio:!LINE)"));
  EXPECT_EQ(problems_of(gpio_ini(chip() + "PROBE_LINE = modbus:0:1:di:3\n")),
            problem_at(kFirst + 2,
                       "[GPIO] PROBE_LINE: 'modbus:0:1:di:3': this input is read in the gpio "
                       "driver's base thread, so it takes only a gpio line (LINE, gpio:LINE or "
                       "gpio:!LINE); [CNCD] PROBE_INPUT takes a gpio: or sim: probe"));
  EXPECT_EQ(problems_of(gpio_joint("HOME_SWITCH_LINE = gpio:!5\nHOME_SWITCH_ACTIVE_LOW = 1\n")),
            problem_at(kFirst + 4,
                       "[JOINT_2] HOME_SWITCH_LINE: 'gpio:!5': active low is given twice, by "
                       "'!' and by HOME_SWITCH_ACTIVE_LOW = 1: give it once"));
  EXPECT_EQ(problems_of(gpio_ini("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = gpio:!1\n"
                                 "DIR_LINE = 2\n" +
                                 chip())),
            problem_at(kFirst + 2,
                       "[JOINT_2] STEP_LINE: 'gpio:!1': STEP_LINE takes no '!': there is no "
                       "STEP_ACTIVE_LOW"));
  EXPECT_EQ(problems_of(gpio_joint("MIN_LIMIT_LINE = sim:min\n")),
            problem_at(kFirst + 4,
                       "[JOINT_2] MIN_LIMIT_LINE: 'sim:min': this input is read in the gpio "
                       "driver's base thread, so it takes only a gpio line (LINE, gpio:LINE or "
                       "gpio:!LINE)"));
}

TEST_F(GpioLineKeysLoadTest, LinesAreComparedAsTheLineTheyName) {
  // The estop line given as an address is still the estop line: no panel key may reuse it.
  EXPECT_EQ(
      problems_of(gpio_ini(chip() + "ESTOP_LINE = gpio:!GPIO4\n[PANEL]\nRESET = gpio:GPIO4\n")),
      problem_at(kFirst + 4,
                 "[PANEL] RESET: 'gpio:GPIO4': gpio line GPIO4 is also [GPIO] ESTOP_LINE (" +
                     at(kFirst + 2) + "), an input too; a panel input has a signal of its own"));
  EXPECT_EQ(problems_of(gpio_joint("MAX_LIMIT_LINE = gpio:!7\n[CNCD]\nFLOOD_OUTPUT = gpio:!7\n")),
            problem_at(kFirst + 6,
                       "[CNCD] FLOOD_OUTPUT: 'gpio:!7': gpio line 7 is also [JOINT_2] "
                       "MAX_LIMIT_LINE (" +
                           at(kFirst + 4) + "), an input; an output cannot share its line"));
  EXPECT_EQ(problems_of(gpio_ini("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = gpio:1\nDIR_LINE = 2\n" +
                                 chip() + "[CNCD]\nDIGITAL_OUTPUT_0 = gpio:1\n")),
            problem_at(kFirst + 7,
                       "[CNCD] DIGITAL_OUTPUT_0: 'gpio:1': gpio line 1 is also [JOINT_2] "
                       "STEP_LINE (" +
                           at(kFirst + 2) + "); an output has one driver"));
}

// The examples show both forms: the panel mill's addresses, the Pi mill's bare lines.
TEST(GpioLineKeysExamplesTest, BothFormsOfTheExamplesLoad) {
  const std::filesystem::path examples = CNCD_CONFIG_EXAMPLES_DIR;
  for (const char* name : {"gpio_panel_mill.ini", "gpio_pi_mill.ini", "gpio_vcd_mill.ini"}) {
    const auto result = load_machine_config(examples / name);
    EXPECT_TRUE(result.ok()) << name << ::testing::PrintToString(strings(result.problems));
    EXPECT_TRUE(result.warnings.empty())
        << name << ::testing::PrintToString(strings(result.warnings));
    ASSERT_TRUE(result.config && result.config->ini) << name;
    const IniFile& ini = *result.config->ini;
    const bool addresses = std::string(name) == "gpio_panel_mill.ini";
    EXPECT_EQ(ini.value("JOINT_0", "ENABLE_LINE"), addresses ? "gpio:!GPIO22" : "GPIO22") << name;
    EXPECT_EQ(ini.find("JOINT_0", "ENABLE_ACTIVE_LOW") != nullptr, !addresses) << name;
  }
  const auto panel = load_machine_config(examples / "gpio_panel_mill.ini");
  ASSERT_TRUE(panel.ok());
  EXPECT_EQ(panel.config->ini->value("GPIO", "ESTOP_LINE"), "gpio:GPIO4");
  const auto pi = load_machine_config(examples / "gpio_pi_mill.ini");
  ASSERT_TRUE(pi.ok());
  EXPECT_EQ(pi.config->ini->value("GPIO", "ESTOP_LINE"), "GPIO4");
}

}  // namespace
}  // namespace cncd::config::test
