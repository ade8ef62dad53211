// [PANEL]: every key read into MachineConfig::panel, the defaults, and each value or pairing
// refused at its FILE:LINE saying what is wrong.
#include <gtest/gtest.h>

#include <string>

#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

class PanelConfigTest : public IoConfigTest {
 protected:
  // What follows minimal_ini() starts at line 42; the [PANEL] header of panel() is line 42,
  // its first key 43.
  static constexpr int kKey = 43;
  static std::string panel(const std::string& keys) { return minimal_ini() + "[PANEL]\n" + keys; }
  std::vector<std::string> refused(const std::string& keys) { return problems_of(panel(keys)); }
  // The one problem of a [PANEL] whose first key is `keys`' line `line` (1-based).
  std::vector<std::string> problem(int line, const std::string& message) const {
    return problem_at(kKey + line - 1, "[PANEL] " + message);
  }
};

const SignalAddress& in(const PanelConfig& p, PanelInput which) {
  return p.input(which);
}

TEST_F(PanelConfigTest, NoSectionNoPanel) {
  const MachineConfig c = loaded(minimal_ini());
  EXPECT_FALSE(c.panel.present);
  for (const auto& a : c.panel.inputs)
    EXPECT_FALSE(a.given());
}

TEST_F(PanelConfigTest, AnEmptySectionHasTheDefaults) {
  const auto result = load(panel(""));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
  const PanelConfig& p = result.config->panel;
  EXPECT_TRUE(p.present);
  EXPECT_EQ(p.debounce_ms, 10);
  EXPECT_EQ(p.door_mode, PanelConfig::DoorMode::hold);
  EXPECT_EQ(p.mpg_counts_per_detent, 4);
  EXPECT_EQ(p.mpg_step_distance, (std::array<double, 3>{0.001, 0.01, 0.1}));
  EXPECT_EQ(p.mpg_mode, PanelConfig::MpgMode::position);
  EXPECT_FALSE(p.mpg_override_feed);
  for (const OverrideKnob& k : p.knobs) {
    EXPECT_EQ(k.per_count, 0.01);
    EXPECT_EQ(k.analog_min, 0);
    EXPECT_EQ(k.analog_max, 10);
    EXPECT_FALSE(k.encoder.given());
    EXPECT_FALSE(k.analog.given());
  }
}

TEST_F(PanelConfigTest, AnInchMachineStepsInTenThousandths) {
  const MachineConfig c =
      loaded(replace_line(minimal_ini(), 7, "LINEAR_UNITS = inch") + "[PANEL]\n");
  EXPECT_EQ(c.panel.mpg_step_distance, (std::array<double, 3>{0.0001, 0.001, 0.01}));
  const MachineConfig given = loaded(replace_line(minimal_ini(), 7, "LINEAR_UNITS = inch") +
                                     "[PANEL]\nMPG_STEP_10_DISTANCE = 0.005\n");
  EXPECT_EQ(given.panel.mpg_step_distance, (std::array<double, 3>{0.0001, 0.005, 0.01}));
}

TEST_F(PanelConfigTest, EveryKeyLoads) {
  std::string keys =
      "DEBOUNCE_MS = 25\nDOOR_MODE = ESTOP\nMPG_COUNTS_PER_DETENT = 100\n"
      "MPG_STEP_1_DISTANCE = 0.002\nMPG_STEP_10_DISTANCE = 0.02\nMPG_STEP_100_DISTANCE = 0.2\n"
      "MPG_MODE = velocity\nMPG_OVERRIDE = feed\nMPG_COUNTS = sim:mpg\n"
      "FEED_OVERRIDE_A = sim:fa\nFEED_OVERRIDE_B = sim:fb\nFEED_OVERRIDE_SCALE = 0.05\n"
      "RAPID_OVERRIDE_COUNTS = modbus:0:1:hr:7\n"
      "SPINDLE_OVERRIDE_ANALOG = modbus:0:1:ir:8\nSPINDLE_OVERRIDE_ANALOG_MIN = 100\n"
      "SPINDLE_OVERRIDE_ANALOG_MAX = 4000\n";
  for (int i = 0; i < kPanelInputs; ++i) {
    const std::string key = panel_input_key(static_cast<PanelInput>(i));
    // Only the machine's axes X, Y, Z.
    if ((key.starts_with("JOG_") || key.starts_with("MPG_AXIS_")) &&
        key.find_first_of("ABCUVW", key.starts_with("JOG_") ? 4 : 9) ==
            (key.starts_with("JOG_") ? 4u : 9u)) {
      continue;
    }
    keys += key + " = sim:in_" + std::to_string(i) + "\n";
  }
  for (int l = 0; l < kPanelLights; ++l) {
    keys += std::string(panel_light_key(static_cast<PanelLight>(l))) + " = sim:light_" +
            std::to_string(l) + "\n";
  }
  const auto result = load(panel(keys + "[MODBUS_0]\nHOST = 127.0.0.1\n"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_TRUE(result.warnings.empty()) << ::testing::PrintToString(strings(result.warnings));
  const PanelConfig& p = result.config->panel;
  EXPECT_EQ(p.debounce_ms, 25);
  EXPECT_EQ(p.door_mode, PanelConfig::DoorMode::estop);
  EXPECT_EQ(p.mpg_counts_per_detent, 100);
  EXPECT_EQ(p.mpg_step_distance, (std::array<double, 3>{0.002, 0.02, 0.2}));
  EXPECT_EQ(p.mpg_mode, PanelConfig::MpgMode::velocity);
  EXPECT_TRUE(p.mpg_override_feed);
  EXPECT_EQ(p.mpg.counts.name, "mpg");
  EXPECT_FALSE(p.mpg.a.given());
  const OverrideKnob& feed = p.knobs[static_cast<int>(PanelAnalog::feed_override)];
  EXPECT_EQ(feed.encoder.a.name, "fa");
  EXPECT_EQ(feed.encoder.b.name, "fb");
  EXPECT_EQ(feed.per_count, 0.05);
  const OverrideKnob& rapid = p.knobs[static_cast<int>(PanelAnalog::rapid_override)];
  EXPECT_EQ(rapid.encoder.counts.table, Table::holding);
  EXPECT_EQ(rapid.encoder.counts.address, 7);
  const OverrideKnob& spindle = p.knobs[static_cast<int>(PanelAnalog::spindle_override)];
  EXPECT_EQ(spindle.analog.table, Table::input);
  EXPECT_EQ(spindle.analog_min, 100);
  EXPECT_EQ(spindle.analog_max, 4000);
  EXPECT_EQ(in(p, PanelInput::cycle_start).name, "in_0");
  EXPECT_EQ(in(p, PanelInput::cycle_start).source.line, kKey + 16);
  EXPECT_EQ(in(p, PanelInput::mpg_step_100).name,
            "in_" + std::to_string(static_cast<int>(PanelInput::mpg_step_100)));
  const auto jog_minus_z = static_cast<int>(PanelInput::jog_minus_x) + 2;
  EXPECT_EQ(p.inputs[jog_minus_z].name, "in_" + std::to_string(jog_minus_z));
  const auto mpg_axis_y = static_cast<int>(PanelInput::mpg_axis_x) + 1;
  EXPECT_EQ(p.inputs[mpg_axis_y].name, "in_" + std::to_string(mpg_axis_y));
  EXPECT_FALSE(p.inputs[static_cast<int>(PanelInput::mpg_axis_x) + 3].given());  // no A axis
  EXPECT_EQ(p.lights[static_cast<int>(PanelLight::lamp_feed_hold)].name, "light_4");
}

TEST_F(PanelConfigTest, EvdevAddressesLoadForTheirUses) {
  const std::string dev = "evdev:/dev/input/by-id/usb-Contour_Design_ShuttleXpress-event-if00:";
  const MachineConfig c = loaded(panel("CYCLE_START = " + dev + "btn_4\nMPG_COUNTS = " + dev +
                                       "REL_DIAL\nFEED_OVERRIDE_ANALOG = " + dev + "ABS_X\n"));
  const SignalAddress& start = c.panel.input(PanelInput::cycle_start);
  EXPECT_EQ(start.kind, Kind::evdev);
  EXPECT_EQ(start.device, "/dev/input/by-id/usb-Contour_Design_ShuttleXpress-event-if00");
  EXPECT_EQ(start.code, "BTN_4");
  EXPECT_EQ(c.panel.mpg.counts.code, "REL_DIAL");
  EXPECT_EQ(c.panel.knobs[0].analog.code, "ABS_X");
}

TEST_F(PanelConfigTest, RangesAndChoicesAreRefusedAtTheirLine) {
  EXPECT_EQ(refused("DEBOUNCE_MS = 1001\n"),
            problem(1, "DEBOUNCE_MS: 1001 is out of range: must be between 0 and 1000 ms"));
  EXPECT_EQ(refused("DEBOUNCE_MS = -1\n"),
            problem(1, "DEBOUNCE_MS: -1 is out of range: must be between 0 and 1000 ms"));
  EXPECT_EQ(
      refused("MPG_COUNTS_PER_DETENT = 0\n"),
      problem(1, "MPG_COUNTS_PER_DETENT: 0 is out of range: must be between 1 and 10000 counts"));
  EXPECT_EQ(
      refused("MPG_COUNTS_PER_DETENT = 10001\n"),
      problem(1,
              "MPG_COUNTS_PER_DETENT: 10001 is out of range: must be between 1 and 10000 counts"));
  EXPECT_EQ(refused("MPG_STEP_10_DISTANCE = 0\n"),
            problem(1, "MPG_STEP_10_DISTANCE: 0 is out of range: must be greater than 0 units"));
  EXPECT_EQ(
      refused("FEED_OVERRIDE_SCALE = -0.01\n"),
      problem(1, "FEED_OVERRIDE_SCALE: -0.01 is out of range: must be greater than 0 ratio/count"));
  EXPECT_EQ(refused("RAPID_OVERRIDE_SCALE = inf\n"),
            problem(1, "RAPID_OVERRIDE_SCALE: 'inf' is not a finite number"));
  EXPECT_EQ(refused("DOOR_MODE = open\n"),
            problem(1, "DOOR_MODE: unknown value 'open'; expected one of hold, estop"));
  EXPECT_EQ(refused("MPG_MODE = jog\n"),
            problem(1, "MPG_MODE: unknown value 'jog'; expected one of position, velocity"));
  EXPECT_EQ(refused("MPG_OVERRIDE = rapid\n"),
            problem(1, "MPG_OVERRIDE: unknown value 'rapid'; expected one of none, feed"));
  EXPECT_EQ(refused("SPINDLE_OVERRIDE_ANALOG_MAX = 0\n"),
            problem(1,
                    "SPINDLE_OVERRIDE_ANALOG_MAX: SPINDLE_OVERRIDE_ANALOG_MAX 0 must be above "
                    "SPINDLE_OVERRIDE_ANALOG_MIN 0"));
  EXPECT_EQ(refused("FEED_OVERRIDE_ANALOG_MIN = 12\n"),
            problem(1,
                    "FEED_OVERRIDE_ANALOG_MIN: FEED_OVERRIDE_ANALOG_MAX 10 must be above "
                    "FEED_OVERRIDE_ANALOG_MIN 12"));
}

TEST_F(PanelConfigTest, UnknownKeysAndAxesTheMachineLacksAreRefused) {
  EXPECT_EQ(refused("JOG_A_PLUS = sim:a\n"),
            problem(1,
                    "JOG_A_PLUS: the machine has no axis A ([TRAJ] COORDINATES = XYZ): jog "
                    "buttons and MPG axis switches are for its axes"));
  EXPECT_EQ(refused("MPG_AXIS_Q = sim:q\n"),
            problem(1,
                    "MPG_AXIS_Q: the machine has no axis Q ([TRAJ] COORDINATES = XYZ): jog "
                    "buttons and MPG axis switches are for its axes"));
  EXPECT_EQ(refused("CYCLE_STRAT = sim:go\n"),
            problem(1,
                    "CYCLE_STRAT: unknown key in the panel's section; did you mean "
                    "CYCLE_START?"));
  // A repeated key is a warning, as everywhere.
  const auto twice = load(panel("STOP = sim:s\nSTOP = sim:t\n"));
  EXPECT_TRUE(twice.ok());
  EXPECT_EQ(strings(twice.warnings),
            problem(2,
                    "STOP: given again with another value (sim:t), which is ignored: the "
                    "first, at line 43 (sim:s), is used"));
}

TEST_F(PanelConfigTest, EncodersAndCountersMustBeWholeAndSingle) {
  EXPECT_EQ(refused("MPG_A = sim:a\n"),
            problem(1, "MPG_A: MPG_A needs MPG_B: an encoder has two channels, A and B"));
  EXPECT_EQ(refused("FEED_OVERRIDE_B = sim:b\n"),
            problem(1,
                    "FEED_OVERRIDE_B: FEED_OVERRIDE_B needs FEED_OVERRIDE_A: an encoder has "
                    "two channels, A and B"));
  EXPECT_EQ(refused("MPG_A = sim:a\nMPG_B = sim:b\nMPG_COUNTS = sim:c\n"),
            problem(3,
                    "MPG_COUNTS: give the count once: MPG_A/MPG_B (an encoder) or MPG_COUNTS "
                    "(a counter), not both"));
  EXPECT_EQ(refused("RAPID_OVERRIDE_COUNTS = sim:c\nRAPID_OVERRIDE_ANALOG = sim:v\n"),
            problem(2,
                    "RAPID_OVERRIDE_ANALOG: a knob is an encoder or an analog input, not "
                    "both: RAPID_OVERRIDE_COUNTS is given too"));
}

TEST_F(PanelConfigTest, DescribeListsTheWiring) {
  EXPECT_NE(describe(loaded(minimal_ini())).find("Panel:        none (no [PANEL])\n"),
            std::string::npos);
  const std::string text = describe(loaded(
      panel("DOOR_MODE = estop\nCYCLE_START = sim:go\nJOG_Y_MINUS = sim:ym\nMPG_AXIS_Z = sim:mz\n"
            "MPG_A = sim:a\nMPG_B = sim:b\nMPG_MODE = velocity\nMPG_COUNTS_PER_DETENT = 100\n"
            "FEED_OVERRIDE_COUNTS = sim:fc\nSPINDLE_OVERRIDE_ANALOG = sim:sa\n"
            "SPINDLE_OVERRIDE_ANALOG_MAX = 5\nLAMP_CYCLE_START = sim:lamp\n")));
  for (const char* expected : {
           "Panel:        debounce 10 ms, door trips the estop\n",
           "  CYCLE_START = sim:go\n",
           "  JOG_Y_MINUS = sim:ym\n",
           "  MPG_AXIS_Z = sim:mz\n",
           "  MPG: encoder A sim:a, B sim:b, 100 counts a detent, velocity mode, steps 0.001 / "
           "0.01 / 0.1 mm\n",
           "  feed override knob: counter sim:fc, 1 % a count\n",
           "  spindle override knob: analog sim:sa, 0 .. 5 over the override's range\n",
           "  LAMP_CYCLE_START = sim:lamp\n",
       }) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\nin\n" << text;
  }
  EXPECT_EQ(text.find("rapid override knob"), std::string::npos) << text;
  EXPECT_EQ(text.find("FEED_HOLD"), std::string::npos) << text;
}

TEST_F(PanelConfigTest, TheExamplePanelsLoadWithoutProblemsOrWarnings) {
  const std::filesystem::path examples = CNCD_CONFIG_EXAMPLES_DIR;
  const auto sim = load_machine_config(examples / "sim_panel_mill.ini");
  ASSERT_TRUE(sim.ok()) << ::testing::PrintToString(strings(sim.problems));
  EXPECT_TRUE(sim.warnings.empty()) << ::testing::PrintToString(strings(sim.warnings));
  const PanelConfig& p = sim.config->panel;
  // Every button and switch of an XYZ mill, and every light.
  for (int i = 0; i < kPanelInputs; ++i) {
    const std::string key = panel_input_key(static_cast<PanelInput>(i));
    const bool other_axis = key.find_first_of("ABCUVW", key.starts_with("JOG_") ? 4 : 9) ==
                            (key.starts_with("JOG_") ? 4u : 9u);
    if ((key.starts_with("JOG_") || key.starts_with("MPG_AXIS_")) && other_axis) continue;
    EXPECT_EQ(p.inputs[static_cast<std::size_t>(i)].kind, Kind::sim) << key;
  }
  for (const SignalAddress& light : p.lights)
    EXPECT_EQ(light.kind, Kind::sim);
  EXPECT_EQ(p.mpg.counts.name, "mpg_counts");
  EXPECT_EQ(p.mpg_counts_per_detent, 100);
  EXPECT_TRUE(p.knobs[0].encoder.counts.given());
  EXPECT_TRUE(p.knobs[1].analog.given());
  EXPECT_TRUE(p.knobs[2].encoder.counts.given());

  const auto gpio = load_machine_config(examples / "gpio_panel_mill.ini");
  ASSERT_TRUE(gpio.ok()) << ::testing::PrintToString(strings(gpio.problems));
  EXPECT_TRUE(gpio.warnings.empty()) << ::testing::PrintToString(strings(gpio.warnings));
  const PanelConfig& g = gpio.config->panel;
  EXPECT_EQ(g.mpg.a.line, "GPIO2");
  EXPECT_EQ(g.mpg.b.line, "GPIO3");
  EXPECT_TRUE(g.input(PanelInput::cycle_start).active_low);
  EXPECT_EQ(g.lights[static_cast<int>(PanelLight::green)].kind, Kind::gpio);
  EXPECT_GT(gpio.config->base_period_ns, 0);
}

TEST_F(PanelConfigTest, SettingsOfWhatIsNotWiredAreWarnedAbout) {
  const auto result =
      load(panel("MPG_COUNTS_PER_DETENT = 100\nMPG_MODE = velocity\nFEED_OVERRIDE_SCALE = 0.02\n"
                 "RAPID_OVERRIDE_COUNTS = sim:r\nRAPID_OVERRIDE_ANALOG_MAX = 5\n"));
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(strings(result.warnings),
            (std::vector<std::string>{
                at(kKey) + ": [PANEL] MPG_COUNTS_PER_DETENT: ignored: no MPG (MPG_A and MPG_B, "
                           "or MPG_COUNTS)",
                at(kKey + 1) + ": [PANEL] MPG_MODE: ignored: no MPG (MPG_A and MPG_B, or "
                               "MPG_COUNTS)",
                at(kKey + 2) + ": [PANEL] FEED_OVERRIDE_SCALE: ignored: no encoder "
                               "(FEED_OVERRIDE_A and _B, or FEED_OVERRIDE_COUNTS)",
                at(kKey + 4) + ": [PANEL] RAPID_OVERRIDE_ANALOG_MAX: ignored: no analog input "
                               "(RAPID_OVERRIDE_ANALOG)"}));
  // A misspelt axis key is guessed with its own letter.
  EXPECT_EQ(refused("JOG_Y_PLSU = sim:y\n"),
            problem(1,
                    "JOG_Y_PLSU: unknown key in the panel's section; did you mean "
                    "JOG_Y_PLUS?"));
}

}  // namespace
}  // namespace cncd::config::test
