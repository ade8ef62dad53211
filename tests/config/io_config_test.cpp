// The [CNCD] signals, user M codes, the probe input, the tool change and what the I/O
// sections default to: each value read, each bad one refused at its FILE:LINE.
#include <string>
#include <vector>

#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

TEST_F(IoConfigTest, DefaultsWithoutTheSections) {
  const MachineConfig c = loaded(minimal_ini());
  const SpindleConfig& s = c.spindle;
  EXPECT_FALSE(s.present);
  EXPECT_EQ(s.driver, SpindleDriver::sim);
  EXPECT_EQ(s.max_forward_velocity, 1e99);
  EXPECT_EQ(s.min_forward_velocity, 0);
  EXPECT_EQ(s.max_reverse_velocity, 1e99);
  EXPECT_EQ(s.min_reverse_velocity, 0);
  EXPECT_EQ(s.increment, 100);
  EXPECT_EQ(s.acceleration, 0);
  EXPECT_EQ(s.at_speed_tolerance, 0.05);
  EXPECT_EQ(s.at_speed_timeout_s, 10);
  EXPECT_FALSE(s.stop_on_pause);
  EXPECT_FALSE(s.enable.given());
  EXPECT_EQ(s.modbus, -1);
  EXPECT_EQ(s.slave, 1);
  EXPECT_EQ(s.status_table, Table::input);
  EXPECT_FALSE(c.io.flood.given());
  for (const auto& a : c.io.digital_outputs)
    EXPECT_FALSE(a.given());
  EXPECT_EQ(c.io.user_m_timeout_s, 60);
  // No PROGRAM_PREFIX: the first program directory, the INI's own.
  EXPECT_EQ(c.io.user_m_path, std::vector<std::filesystem::path>{c.program_dirs.front()});
  EXPECT_FALSE(c.tool_change.has_position);
  EXPECT_FALSE(c.tool_change.quill_up);
  EXPECT_FALSE(c.tool_change.with_spindle_on);
  EXPECT_NE(describe(c).find("Spindle:      driver sim (no [SPINDLE_0]"), std::string::npos);
}

TEST_F(IoConfigTest, TheProbeInputIsGpioOrSimAndGivenOnce) {
  EXPECT_EQ(loaded(minimal_ini() + "[CNCD]\nPROBE_INPUT = sim:probe\n").io.probe_input.name,
            "probe");
  EXPECT_EQ(problems_of(minimal_ini() + "[MODBUS_0]\nHOST = x\n[CNCD]\n"
                                        "PROBE_INPUT = modbus:0:1:di:4\n"),
            (std::vector<std::string>{
                at(kFirst + 2) +
                ": [CNCD] PROBE_INPUT: 'modbus:0:1:di:4': a Modbus input answers an update period "
                "(UPDATE_PERIOD_MS) or more late, too late to stop a probe on contact: wire the "
                "probe to a gpio line"}));
  EXPECT_EQ(problems_of(gpio_ini(chip() + "PROBE_LINE = 5\n[CNCD]\nPROBE_INPUT = gpio:6\n")),
            (std::vector<std::string>{
                at(kFirst + 4) +
                ": [CNCD] PROBE_INPUT: give the probe once: [GPIO] PROBE_LINE is given too"}));
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nPROBE_INPUT = modbus:0:1:coil\n").size(), 1U);
}

TEST_F(IoConfigTest, CncdSignalsAndUserMTimeout) {
  const MachineConfig c =
      loaded(minimal_ini() + chip() +
             "[MODBUS_0]\nHOST = 10.0.0.2\n"
             "[CNCD]\nFLOOD_OUTPUT = gpio:!20\nMIST_OUTPUT = sim:mist\nDIGITAL_OUTPUT_0 = "
             "modbus:0:2:coil:0\nDIGITAL_OUTPUT_31 = gpio:21\nANALOG_OUTPUT_15 = modbus:0:2:hr:7\n"
             "DIGITAL_INPUT_3 = modbus:0:2:di:3\nDIGITAL_INPUT_4 = modbus:0:2:coil:0\n"
             "ANALOG_INPUT_0 = modbus:0:2:ir:1\nANALOG_INPUT_1 = sim:temperature\n"
             "USER_M_TIMEOUT = 5\n");
  const IoConfig& io = c.io;
  EXPECT_EQ(io.flood.line, "20");
  EXPECT_TRUE(io.flood.active_low);
  EXPECT_EQ(io.flood.source.line, 47);
  EXPECT_EQ(io.mist.name, "mist");
  EXPECT_EQ(io.digital_outputs[0].table, Table::coil);
  EXPECT_EQ(io.digital_outputs[0].slave, 2);
  EXPECT_EQ(io.digital_outputs[31].line, "21");
  EXPECT_EQ(io.analog_outputs[15].address, 7);
  EXPECT_EQ(io.digital_inputs[3].table, Table::discrete);
  EXPECT_EQ(io.digital_inputs[4].table, Table::coil);  // reading back a coil is fine
  EXPECT_EQ(io.analog_inputs[0].table, Table::input);
  EXPECT_EQ(io.analog_inputs[1].name, "temperature");
  EXPECT_FALSE(io.digital_outputs[1].given());
  EXPECT_EQ(io.user_m_timeout_s, 5);
  const std::string text = describe(c);
  EXPECT_NE(text.find("  flood (M8) = gpio:!20\n  mist (M7) = sim:mist\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("  analog output 15 = modbus:0:2:hr:7\n"), std::string::npos);
}

TEST_F(IoConfigTest, SignalNumbersOutOfRangeAreRefused) {
  EXPECT_EQ(
      problems_of(minimal_ini() + "[CNCD]\nDIGITAL_OUTPUT_32 = sim:a\nANALOG_INPUT_16 = sim:b\n"
                                  "ANALOG_OUTPUT_07 = sim:c\nDIGITAL_INPUT_99999999999 = sim:d\n"),
      (std::vector<std::string>{
          at(43) + ": [CNCD] DIGITAL_OUTPUT_32: number out of range: these are "
                   "DIGITAL_OUTPUT_0 .. DIGITAL_OUTPUT_31",
          at(44) + ": [CNCD] ANALOG_INPUT_16: number out of range: these are "
                   "ANALOG_INPUT_0 .. ANALOG_INPUT_15",
          at(45) + ": [CNCD] ANALOG_OUTPUT_07: write the number without leading zeros; "
                   "these are ANALOG_OUTPUT_0 .. ANALOG_OUTPUT_15",
          at(46) + ": [CNCD] DIGITAL_INPUT_99999999999: number out of range: these are "
                   "DIGITAL_INPUT_0 .. DIGITAL_INPUT_31"}));
}

TEST_F(IoConfigTest, BadAddressIsRefusedAtItsKey) {
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nFLOOD_OUTPUT = relay:3\n"),
            problem_at(43,
                       "[CNCD] FLOOD_OUTPUT: 'relay:3': unknown kind 'relay'; an address is "
                       "gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N, sim:NAME or "
                       "evdev:DEVICE:CODE"));
  // Outside [SPINDLE_0] a bare line is not an address.
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nMIST_OUTPUT = 17\n"),
            problem_at(43,
                       "[CNCD] MIST_OUTPUT: '17': '17' names no kind; an address is "
                       "gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N, sim:NAME or "
                       "evdev:DEVICE:CODE"));
}

TEST_F(IoConfigTest, EachSignalMustBeAbleToGoItsWay) {
  EXPECT_EQ(
      problems_of(minimal_ini() + chip() +
                  "[MODBUS_0]\nHOST = x\n[CNCD]\nDIGITAL_OUTPUT_0 = modbus:0:1:hr:3\n"
                  "DIGITAL_OUTPUT_1 = modbus:0:1:di:3\nANALOG_OUTPUT_0 = gpio:5\n"
                  "ANALOG_OUTPUT_1 = modbus:0:1:coil:4\nDIGITAL_INPUT_0 = modbus:0:1:ir:2\n"
                  "ANALOG_INPUT_0 = gpio:6\nANALOG_INPUT_1 = modbus:0:1:di:2\n"),
      (std::vector<std::string>{
          at(47) + ": [CNCD] DIGITAL_OUTPUT_0: 'modbus:0:1:hr:3': a holding register is not a "
                   "bit: use a coil",
          at(48) + ": [CNCD] DIGITAL_OUTPUT_1: 'modbus:0:1:di:3': a discrete input or input "
                   "register cannot be written: use a coil",
          at(49) + ": [CNCD] ANALOG_OUTPUT_0: 'gpio:5': a gpio line is not analog: use a holding "
                   "register (hr)",
          at(50) + ": [CNCD] ANALOG_OUTPUT_1: 'modbus:0:1:coil:4': an analog output is a holding "
                   "register (hr)",
          at(51) + ": [CNCD] DIGITAL_INPUT_0: 'modbus:0:1:ir:2': a register is not a bit: use a "
                   "discrete input (di) or a coil",
          at(52) + ": [CNCD] ANALOG_INPUT_0: 'gpio:6': a gpio line is not analog: use an input "
                   "(ir) or holding register (hr)",
          at(53) + ": [CNCD] ANALOG_INPUT_1: 'modbus:0:1:di:2': a bit is not analog: use an "
                   "input (ir) or holding register (hr)"}));
}

TEST_F(IoConfigTest, AddressesNeedTheirBusAndChip) {
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nFLOOD_OUTPUT = modbus:3:1:coil:0\n"
                                        "MIST_OUTPUT = gpio:4\n"),
            (std::vector<std::string>{
                at(43) + ": [CNCD] FLOOD_OUTPUT: 'modbus:3:1:coil:0': no section [MODBUS_3] in "
                         "the file",
                at(44) + ": [CNCD] MIST_OUTPUT: 'gpio:4': a gpio line needs [GPIO] CHIP"}));
}

TEST_F(IoConfigTest, AnOutputHasOneDriver) {
  EXPECT_EQ(problems_of(minimal_ini() + chip() +
                        "[MODBUS_0]\nHOST = x\n[CNCD]\nFLOOD_OUTPUT = gpio:20\n"
                        "DIGITAL_OUTPUT_2 = gpio:!20\nMIST_OUTPUT = modbus:0:1:coil:9\n"
                        "DIGITAL_OUTPUT_3 = modbus:0:1:coil:9\nDIGITAL_INPUT_0 = gpio:20\n"),
            (std::vector<std::string>{
                at(48) +
                    ": [CNCD] DIGITAL_OUTPUT_2: 'gpio:!20': gpio line 20 is also [CNCD] "
                    "FLOOD_OUTPUT (" +
                    at(47) + "); an output has one driver",
                at(50) +
                    ": [CNCD] DIGITAL_OUTPUT_3: 'modbus:0:1:coil:9': modbus bus 0 slave 1 coil 9 "
                    "is also [CNCD] MIST_OUTPUT (" +
                    at(49) + "); an output has one driver",
                at(51) +
                    ": [CNCD] DIGITAL_INPUT_0: 'gpio:20': gpio line 20 is also [CNCD] "
                    "FLOOD_OUTPUT (" +
                    at(47) + "), an output; an input cannot share its line"}));
}

TEST_F(IoConfigTest, AnOutputCannotBeTheEstopOrProbeLine) {
  EXPECT_EQ(
      problems_of(gpio_ini("[GPIO]\nCHIP = vcd:/tmp/x.vcd\nESTOP_LINE = 4\nPROBE_LINE = GPIO18\n"
                           "[CNCD]\nFLOOD_OUTPUT = gpio:4\nMIST_OUTPUT = gpio:GPIO18\n"
                           "[SPINDLE_0]\nDRIVER = gpio\nENABLE = !4\n")),
      (std::vector<std::string>{
          at(kFirst + 5) +
              ": [CNCD] FLOOD_OUTPUT: 'gpio:4': gpio line 4 is also [GPIO] "
              "ESTOP_LINE (" +
              at(kFirst + 2) + "), an input; an output cannot share its line",
          at(kFirst + 6) +
              ": [CNCD] MIST_OUTPUT: 'gpio:GPIO18': gpio line GPIO18 is also [GPIO] "
              "PROBE_LINE (" +
              at(kFirst + 3) + "), an input; an output cannot share its line",
          at(kFirst + 9) + ": [SPINDLE_0] ENABLE: '!4': gpio line 4 is also [GPIO] ESTOP_LINE (" +
              at(kFirst + 2) + "), an input; an output cannot share its line"}));
}

TEST_F(IoConfigTest, UserMPathFollowsTheFirstProgramDirectory) {
  std::filesystem::create_directories(dir_ / "mcodes");
  const auto result = load(minimal_ini() +
                           "[DISPLAY]\nPROGRAM_PREFIX = .\n[RS274NGC]\nUSER_M_PATH = "
                           "mcodes:/nonexistent/cncd-m:mcodes/\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const auto& path = result.config->io.user_m_path;
  EXPECT_EQ(path, (std::vector<std::filesystem::path>{
                      std::filesystem::absolute(dir_).lexically_normal(),
                      std::filesystem::absolute(dir_ / "mcodes").lexically_normal(),
                      "/nonexistent/cncd-m"}));
  EXPECT_EQ(strings(result.warnings),
            std::vector<std::string>{
                at(45) + ": [RS274NGC] USER_M_PATH: '/nonexistent/cncd-m' is not a directory "
                         "(yet): no user M code is found there until it is one"});
}

TEST_F(IoConfigTest, ToolChangeKeys) {
  auto c = loaded(minimal_ini() +
                  "[EMCIO]\nTOOL_CHANGE_POSITION = 1 2.5 90\n"
                  "TOOL_CHANGE_QUILL_UP = 1\nTOOL_CHANGE_WITH_SPINDLE_ON = 1\n");
  const ToolChangeConfig& t = c.tool_change;
  EXPECT_TRUE(t.has_position);
  EXPECT_EQ(t.position[0], 1);
  EXPECT_EQ(t.position[1], 2.5);
  EXPECT_EQ(t.position[2], 90);
  EXPECT_TRUE(t.position_given[2]);
  EXPECT_FALSE(t.position_given[3]);
  EXPECT_TRUE(t.quill_up);
  EXPECT_TRUE(t.with_spindle_on);
  EXPECT_NE(describe(c).find("Tool change:  Z to machine zero, move to X1 Y2.5 Z90, spindle "
                             "keeps turning"),
            std::string::npos);
  // Nine numbers on an XYZ machine: the axes it does not have are not checked.
  c = loaded(minimal_ini() + "[EMCIO]\nTOOL_CHANGE_POSITION = 0 0 50 999 0 0 0 0 -999\n");
  EXPECT_TRUE(c.tool_change.position_given[8]);
  EXPECT_EQ(c.tool_change.position[8], -999);
}

TEST_F(IoConfigTest, ToolChangePositionMustBeThreeSixOrNineNumbersInsideTheLimits) {
  EXPECT_EQ(problems_of(minimal_ini() + "[EMCIO]\nTOOL_CHANGE_POSITION = 1 2 3 4\n"),
            problem_at(43,
                       "[EMCIO] TOOL_CHANGE_POSITION: 4 numbers; write 3 (X Y Z), 6 (X Y Z "
                       "A B C) or 9 (X Y Z A B C U V W)"));
  EXPECT_EQ(problems_of(minimal_ini() + "[EMCIO]\nTOOL_CHANGE_POSITION = 1 2 up\n"),
            problem_at(43, "[EMCIO] TOOL_CHANGE_POSITION: 'up' is not a number"));
  EXPECT_EQ(problems_of(minimal_ini() + "[EMCIO]\nTOOL_CHANGE_POSITION = 150 -20 50\n"),
            (std::vector<std::string>{
                at(43) + ": [EMCIO] TOOL_CHANGE_POSITION: X 150 is above [AXIS_X] MAX_LIMIT 100: "
                         "the tool change would leave the soft limits",
                at(43) + ": [EMCIO] TOOL_CHANGE_POSITION: Y -20 is below [AXIS_Y] MIN_LIMIT -10: "
                         "the tool change would leave the soft limits"}));
  EXPECT_EQ(problems_of(replace_line(minimal_ini(), 23, "MIN_LIMIT = 10") +
                        "[EMCIO]\nTOOL_CHANGE_QUILL_UP = 1\n"),
            problem_at(43,
                       "[EMCIO] TOOL_CHANGE_QUILL_UP: Z 0 (machine zero) is below [AXIS_Z] "
                       "MIN_LIMIT 10: the tool change would leave the soft limits"));
}

TEST_F(IoConfigTest, RunFromLineSafeZDefaultsToTheTopOfZAndMustBeWithinItsLimits) {
  const auto plain = loaded(minimal_ini());
  EXPECT_FALSE(plain.cncd.run_from_line_safe_z);
  const auto set = loaded(minimal_ini() + "[CNCD]\nRUN_FROM_LINE_SAFE_Z = 25.5\n");
  EXPECT_EQ(set.cncd.run_from_line_safe_z, 25.5);
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nRUN_FROM_LINE_SAFE_Z = 150\n"),
            problem_at(43,
                       "[CNCD] RUN_FROM_LINE_SAFE_Z: 150 is outside [AXIS_Z] MIN_LIMIT -10 to "
                       "MAX_LIMIT 100: a run from a line could not rise to it"));
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nRUN_FROM_LINE_SAFE_Z = high\n").size(), 1u);
}

}  // namespace
}  // namespace cncd::config::test
