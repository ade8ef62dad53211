// Signal addresses, [SPINDLE_0], the [CNCD] signals, user M codes and the tool change: each
// value read, each bad one refused at its FILE:LINE.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

using Kind = SignalAddress::Kind;
using Table = SignalAddress::Table;

SignalAddress parsed(std::string_view text) {
  SignalAddress a;
  const std::string error = parse_signal_address(text, a);
  EXPECT_EQ(error, "") << text;
  return a;
}

std::string error_of(std::string_view text) {
  SignalAddress a;
  a.name = "untouched";
  const std::string error = parse_signal_address(text, a);
  EXPECT_EQ(a.name, "untouched") << "a refused address leaves its output alone: " << text;
  EXPECT_EQ(a.kind, Kind::none);
  return error;
}

TEST(SignalAddressTest, GpioLineByOffsetOrNameAndActiveLow) {
  auto a = parsed("gpio:17");
  EXPECT_EQ(a.kind, Kind::gpio);
  EXPECT_EQ(a.line, "17");
  EXPECT_FALSE(a.active_low);
  EXPECT_EQ(a.text, "gpio:17");
  a = parsed("  GPIO:!GPIO27 ");
  EXPECT_EQ(a.kind, Kind::gpio);
  EXPECT_EQ(a.line, "GPIO27");
  EXPECT_TRUE(a.active_low);
  EXPECT_EQ(a.text, "GPIO:!GPIO27");
  EXPECT_TRUE(a.given());
  EXPECT_FALSE(SignalAddress{}.given());
}

TEST(SignalAddressTest, ModbusEveryTable) {
  auto a = parsed("modbus:0:1:coil:5");
  EXPECT_EQ(a.kind, Kind::modbus);
  EXPECT_EQ(a.bus, 0);
  EXPECT_EQ(a.slave, 1);
  EXPECT_EQ(a.table, Table::coil);
  EXPECT_EQ(a.address, 5);
  a = parsed("modbus:2:247:hr:65535");
  EXPECT_EQ(a.bus, 2);
  EXPECT_EQ(a.slave, 247);
  EXPECT_EQ(a.table, Table::holding);
  EXPECT_EQ(a.address, 65535);
  EXPECT_EQ(parsed("modbus:0:0:di:0").table, Table::discrete);
  EXPECT_EQ(parsed("MODBUS:0:3:IR:100").table, Table::input);
}

TEST(SignalAddressTest, SimByName) {
  const auto a = parsed("sim:coolant");
  EXPECT_EQ(a.kind, Kind::sim);
  EXPECT_EQ(a.name, "coolant");
}

TEST(SignalAddressTest, GarbageIsRefusedSayingWhatIsWrong) {
  const std::string syntax =
      "an address is gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N or sim:NAME";
  EXPECT_EQ(error_of(""), "empty address; " + syntax);
  EXPECT_EQ(error_of("17"), "'17' names no kind; " + syntax);
  EXPECT_EQ(error_of("pin:17"), "unknown kind 'pin'; " + syntax);
  EXPECT_EQ(error_of(":17"), "missing the kind before ':'; " + syntax);
  EXPECT_EQ(error_of("gpio:"), "empty line");
  EXPECT_EQ(error_of("gpio:!"), "empty line");
  EXPECT_EQ(error_of("gpio:1 7"), "line '1 7' contains a blank or control character");
  EXPECT_EQ(error_of("gpio:a:b"), "line 'a:b' is not an offset or a line name");
  EXPECT_EQ(error_of("gpio:!!3"), "line '!3' is not an offset or a line name");
  const std::string usage = ": write modbus:BUS:SLAVE:coil|hr|di|ir:N";
  EXPECT_EQ(error_of("modbus:"), "missing bus");
  EXPECT_EQ(error_of("modbus:0"), "missing the slave" + usage);
  EXPECT_EQ(error_of("modbus:0:1"), "missing the table (coil, hr, di or ir)" + usage);
  EXPECT_EQ(error_of("modbus:0:1:coil"), "missing the coil or register number" + usage);
  EXPECT_EQ(error_of("modbus:0:1::4"), "missing the table: coil, hr, di or ir");
  EXPECT_EQ(error_of("modbus:0:1:coil:"), "missing coil");
  EXPECT_EQ(error_of("modbus:0:1:coil:4:5"), "too many parts" + usage);
  EXPECT_EQ(error_of("modbus:x:1:coil:4"), "bus 'x' is not a whole number");
  EXPECT_EQ(error_of("modbus:100:1:coil:4"), "bus 100 is out of range 0..99");
  EXPECT_EQ(error_of("modbus:0:1.5:coil:4"), "slave '1.5' is not a whole number");
  EXPECT_EQ(error_of("modbus:0:248:coil:4"), "slave 248 is out of range 0..247");
  EXPECT_EQ(error_of("modbus:0:-1:coil:4"), "slave -1 is out of range 0..247");
  EXPECT_EQ(error_of("modbus:0:1:reg:4"), "unknown table 'reg': expected coil, hr, di or ir");
  EXPECT_EQ(error_of("modbus:0:1:hr:65536"), "register 65536 is out of range 0..65535");
  EXPECT_EQ(error_of("modbus:0:1:ir:99999999999999"),
            "register 99999999999999 is out of range 0..65535");
  EXPECT_EQ(error_of("modbus:0:1:di:0x10"), "discrete input '0x10' is not a whole number");
  EXPECT_EQ(error_of("sim:"), "empty signal name");
  EXPECT_EQ(error_of("sim:a:b"), "signal name 'a:b' contains ':'");
  EXPECT_EQ(error_of("sim:a\tb"), "signal name 'a?b' contains a blank or control character");
}

TEST(SignalKeysTest, EveryNewKeyIsInTheTable) {
  for (const char* key : {"DRIVER", "MAX_FORWARD_VELOCITY", "MIN_REVERSE_VELOCITY", "ENABLE", "PWM",
                          "ENCODER_PPR", "STATUS_TABLE", "FAULT_BIT"}) {
    ASSERT_NE(find_key_spec("SPINDLE_0", key), nullptr) << key;
  }
  EXPECT_EQ(find_key_spec("CNCD", "DIGITAL_OUTPUT_31")->key, "DIGITAL_OUTPUT_n");
  EXPECT_EQ(find_key_spec("CNCD", "ANALOG_INPUT_3")->type, KeyType::signal);
  EXPECT_EQ(find_key_spec("CNCD", "DIGITAL_OUTPUT_"), nullptr);
  EXPECT_EQ(find_key_spec("CNCD", "DIGITAL_OUTPUT_x"), nullptr);
  EXPECT_NE(find_key_spec("RS274NGC", "USER_M_PATH"), nullptr);
  EXPECT_NE(find_key_spec("EMCIO", "TOOL_CHANGE_POSITION"), nullptr);
  EXPECT_EQ(find_key_spec("SPINDLE_1", "DRIVER"), nullptr);
}

class IoConfigTest : public MachineIniTest {
 protected:
  // minimal_ini() with a base thread and a VCD chip: what gpio signals need. What `extra`
  // holds starts at line 43 (kFirst).
  static constexpr int kFirst = 43;
  static std::string gpio_ini(const std::string& extra) {
    return replace_line(minimal_ini(), 4, "SERVO_PERIOD = 1000000\nBASE_PERIOD = 25000") + extra;
  }
  static std::string chip() { return "[GPIO]\nCHIP = vcd:/tmp/cncd-io-test.vcd\n"; }
  MachineConfig loaded(const std::string& ini) {
    const auto result = load(ini);
    EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
    return result.ok() ? *result.config : MachineConfig{};
  }
  std::vector<std::string> warnings_of(const std::string& ini) {
    return strings(load(ini).warnings);
  }
};

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

TEST_F(IoConfigTest, GpioSpindleKeys) {
  const MachineConfig c = loaded(gpio_ini(
      chip() +
      "[SPINDLE_0]\nDRIVER = gpio\nMAX_FORWARD_VELOCITY = 24000\nMIN_FORWARD_VELOCITY = 6000\n"
      "INCREMENT = 500\nACCELERATION = 4000\nAT_SPEED_TOLERANCE = 0.1\nAT_SPEED_TIMEOUT = 5\n"
      "STOP_ON_PAUSE = YES\nENABLE = 17\nDIRECTION = !GPIO18   # high for M4\nPWM = gpio:12\n"
      "PWM_FREQUENCY = 500\nPWM_MIN_DUTY = 0.1\nENCODER_A = gpio:5\nENCODER_B = gpio:6\n"
      "ENCODER_INDEX = sim:index\nENCODER_PPR = 100\n"));
  const SpindleConfig& s = c.spindle;
  EXPECT_TRUE(s.present);
  EXPECT_EQ(s.driver, SpindleDriver::gpio);
  EXPECT_EQ(s.max_forward_velocity, 24000);
  EXPECT_EQ(s.min_forward_velocity, 6000);
  EXPECT_EQ(s.max_reverse_velocity, 24000);  // unset: the forward ones
  EXPECT_EQ(s.min_reverse_velocity, 6000);
  EXPECT_EQ(s.increment, 500);
  EXPECT_EQ(s.acceleration, 4000);
  EXPECT_EQ(s.at_speed_tolerance, 0.1);
  EXPECT_EQ(s.at_speed_timeout_s, 5);
  EXPECT_TRUE(s.stop_on_pause);
  EXPECT_EQ(s.enable.kind, Kind::gpio);
  EXPECT_EQ(s.enable.line, "17");
  EXPECT_EQ(s.enable.text, "17");
  EXPECT_EQ(s.enable.source.line, kFirst + 11);
  EXPECT_EQ(s.direction.line, "GPIO18");
  EXPECT_TRUE(s.direction.active_low);
  EXPECT_EQ(s.pwm.line, "12");
  EXPECT_EQ(s.pwm_frequency, 500);
  EXPECT_EQ(s.pwm_min_duty, 0.1);
  EXPECT_EQ(s.encoder_a.line, "5");
  EXPECT_EQ(s.encoder_b.line, "6");
  EXPECT_EQ(s.encoder_index.kind, Kind::sim);
  EXPECT_EQ(s.encoder_ppr, 100);
  EXPECT_EQ(s.source.line, kFirst + 2);
  const std::string text = describe(c);
  EXPECT_NE(text.find("Spindle:      driver gpio\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  forward 6000 .. 24000 rpm, reverse 6000 .. 24000 rpm"), std::string::npos);
  EXPECT_NE(text.find("  acceleration 4000 rpm/s, at speed within 10 % in 5 s, stops on pause"),
            std::string::npos);
  EXPECT_NE(text.find("  enable = 17\n  direction = !GPIO18\n  pwm = gpio:12 at 500 Hz"),
            std::string::npos)
      << text;
}

TEST_F(IoConfigTest, ReverseLimitsAreMagnitudesAsInLinuxCnc) {
  auto c = loaded(minimal_ini() +
                  "[SPINDLE_0]\nMAX_FORWARD_VELOCITY = 3000\nMAX_REVERSE_VELOCITY = -1000\n"
                  "MIN_REVERSE_VELOCITY = -100\n");
  EXPECT_EQ(c.spindle.max_reverse_velocity, 1000);
  EXPECT_EQ(c.spindle.min_reverse_velocity, 100);
  EXPECT_EQ(c.spindle.driver, SpindleDriver::sim);
  // 0: never in reverse; the forward minimum does not make that a contradiction.
  c = loaded(minimal_ini() + "[SPINDLE_0]\nMIN_FORWARD_VELOCITY = 500\nMAX_REVERSE_VELOCITY = 0\n");
  EXPECT_EQ(c.spindle.max_reverse_velocity, 0);
  EXPECT_EQ(c.spindle.min_reverse_velocity, 0);
  EXPECT_NE(describe(c).find("reverse never"), std::string::npos);
}

TEST_F(IoConfigTest, ModbusSpindleKeys) {
  const MachineConfig c = loaded(
      minimal_ini() +
      "[MODBUS_1]\nHOST = 127.0.0.1\n"
      "[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\nSLAVE = 7\nSPEED_SCALE = 0.5\n"
      "COMMAND_REGISTER = 8192\nSPEED_REGISTER = 8193\nACTUAL_SPEED_REGISTER = -1\n"
      "STATUS_REGISTER = 12288\nACTUAL_SPEED_TABLE = hr\nSTATUS_TABLE = HR\nCOMMAND_STOP = 5\n"
      "COMMAND_FORWARD = 18\nCOMMAND_REVERSE = 34\nRUNNING_BIT = -1\nAT_SPEED_BIT = 3\n"
      "FAULT_BIT = 15\n");
  const SpindleConfig& s = c.spindle;
  EXPECT_EQ(s.driver, SpindleDriver::modbus);
  EXPECT_EQ(s.modbus, 1);
  EXPECT_EQ(s.slave, 7);
  EXPECT_EQ(s.speed_scale, 0.5);
  EXPECT_EQ(s.command_register, 8192);
  EXPECT_EQ(s.speed_register, 8193);
  EXPECT_EQ(s.actual_speed_register, -1);
  EXPECT_EQ(s.status_register, 12288);
  EXPECT_EQ(s.actual_speed_table, Table::holding);
  EXPECT_EQ(s.status_table, Table::holding);
  EXPECT_EQ(s.command_stop, 5);
  EXPECT_EQ(s.command_forward, 18);
  EXPECT_EQ(s.command_reverse, 34);
  EXPECT_EQ(s.running_bit, -1);
  EXPECT_EQ(s.at_speed_bit, 3);
  EXPECT_EQ(s.fault_bit, 15);
  EXPECT_NE(describe(c).find("  MODBUS_1 slave 7, command hr 8192"), std::string::npos);
}

TEST_F(IoConfigTest, ModbusSpindlePositionKeys) {
  const std::string head = minimal_ini() +
                           "[MODBUS_1]\nHOST = 127.0.0.1\n"
                           "[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\n";
  EXPECT_EQ(loaded(head).spindle.position_register, -1);
  const MachineConfig c =
      loaded(head +
             "POSITION_REGISTER = 100\nPOSITION_TABLE = hr\nPOSITION_WIDTH = 16\n"
             "POSITION_SCALE = -4096\n");
  const SpindleConfig& s = c.spindle;
  EXPECT_EQ(s.position_register, 100);
  EXPECT_EQ(s.position_table, Table::holding);
  EXPECT_EQ(s.position_width, 16);
  EXPECT_EQ(s.position_scale, -4096);
  EXPECT_NE(describe(c).find("  position holding register 100, 16 bits, -4096 counts/rev"),
            std::string::npos)
      << describe(c);
  const MachineConfig wide =
      loaded(head + "POSITION_REGISTER = 7\nWORD_ORDER = LOW_FIRST\nPOSITION_SCALE = 10000\n");
  EXPECT_EQ(wide.spindle.position_width, 32);
  EXPECT_FALSE(wide.spindle.position_high_first);
  EXPECT_EQ(wide.spindle.position_table, Table::input);
  EXPECT_NE(describe(wide).find("  position input register 7, 32 bits, low word first, 10000 "
                                "counts/rev"),
            std::string::npos);
  // A bus read that seldom is worth a word.
  const std::string slow = minimal_ini() +
                           "[MODBUS_1]\nHOST = 127.0.0.1\nUPDATE_PERIOD_MS = 20\n"
                           "[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\n";
  EXPECT_EQ(warnings_of(slow + "POSITION_REGISTER = 7\nPOSITION_SCALE = 4096\n"),
            (std::vector<std::string>{
                at(48) + ": [SPINDLE_0] POSITION_REGISTER: [MODBUS_1] UPDATE_PERIOD_MS = 20: a "
                         "rigid tap on a spindle read that seldom may be off its helix by more "
                         "than pitch x 0.02; keep it at 10 or less"}));
  EXPECT_TRUE(warnings_of(slow).empty());
  // Without a register the other keys do nothing, and say so.
  EXPECT_EQ(warnings_of(head + "POSITION_SCALE = 4096\n"),
            (std::vector<std::string>{
                at(47) + ": [SPINDLE_0] POSITION_SCALE: ignored: no POSITION_REGISTER"}));
}

TEST_F(IoConfigTest, BadSpindlePositionKeysAreRefusedAtTheirLines) {
  const std::string head = minimal_ini() +
                           "[MODBUS_1]\nHOST = 127.0.0.1\n"
                           "[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\n";
  const int first = 47;  // the first line after `head`
  EXPECT_EQ(problems_of(head + "POSITION_REGISTER = 3\n"),
            (std::vector<std::string>{at(first) +
                                      ": [SPINDLE_0] POSITION_REGISTER: POSITION_REGISTER needs "
                                      "POSITION_SCALE, the position counts a revolution"}));
  EXPECT_EQ(problems_of(head + "POSITION_REGISTER = 3\nPOSITION_SCALE = 0\n"),
            (std::vector<std::string>{at(first + 1) +
                                      ": [SPINDLE_0] POSITION_SCALE: must not be 0 (counts a "
                                      "revolution)"}));
  EXPECT_EQ(problems_of(head + "POSITION_REGISTER = 3\nPOSITION_WIDTH = 16\n"
                               "POSITION_SCALE = 20000\n"),
            (std::vector<std::string>{at(first + 2) +
                                      ": [SPINDLE_0] POSITION_SCALE: a 16-bit counter wraps "
                                      "every 65536 counts: a revolution must be at most a "
                                      "quarter of that (16384)"}));
  EXPECT_EQ(problems_of(head + "POSITION_REGISTER = 65535\nPOSITION_SCALE = 4096\n"),
            (std::vector<std::string>{at(first) +
                                      ": [SPINDLE_0] POSITION_REGISTER: a 32-bit position takes "
                                      "two registers: at most 65534"}));
  EXPECT_EQ(problems_of(head + "POSITION_REGISTER = 3\nPOSITION_SCALE = 4096\n"
                               "POSITION_WIDTH = 24\n"),
            (std::vector<std::string>{at(first + 2) +
                                      ": [SPINDLE_0] POSITION_WIDTH: unknown value '24'; expected "
                                      "one of 16, 32"}));
}

TEST_F(IoConfigTest, BadSpindleValuesAreRefusedAtTheirLines) {
  const int at_spindle = 43;  // [SPINDLE_0] comes right after minimal_ini()
  EXPECT_EQ(
      problems_of(minimal_ini() +
                  "[SPINDLE_0]\nDRIVER = vfd\nAT_SPEED_TOLERANCE = 2\nAT_SPEED_TIMEOUT = 0\n"
                  "MIN_FORWARD_VELOCITY = -1\n"),
      (std::vector<std::string>{
          at(at_spindle) +
              ": [SPINDLE_0] DRIVER: unknown value 'vfd'; expected one of none, sim, gpio, modbus",
          at(at_spindle + 1) +
              ": [SPINDLE_0] AT_SPEED_TOLERANCE: 2 is out of range: must be between 0 and 1 ratio",
          at(at_spindle + 2) +
              ": [SPINDLE_0] AT_SPEED_TIMEOUT: 0 is out of range: must be greater than 0 s",
          at(at_spindle + 3) +
              ": [SPINDLE_0] MIN_FORWARD_VELOCITY: -1 is out of range: must be at least 0 rpm"}));
  EXPECT_EQ(problems_of(minimal_ini() + "[MODBUS_0]\nHOST = x\n[SPINDLE_0]\nDRIVER = modbus\n"
                                        "MODBUS = 0\nFAULT_BIT = 16\nSTATUS_TABLE = coil\n"),
            (std::vector<std::string>{
                at(47) + ": [SPINDLE_0] FAULT_BIT: 16 is out of range: must be between -1 and 15",
                at(48) + ": [SPINDLE_0] STATUS_TABLE: unknown value 'coil'; expected one of ir, "
                         "hr"}));
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

TEST_F(IoConfigTest, MinimumAboveMaximumIsRefused) {
  EXPECT_EQ(problems_of(minimal_ini() + "[SPINDLE_0]\nMAX_FORWARD_VELOCITY = 1000\n"
                                        "MIN_FORWARD_VELOCITY = 2000\n"),
            problem_at(44,
                       "[SPINDLE_0] MIN_FORWARD_VELOCITY: 2000 must not be above "
                       "MAX_FORWARD_VELOCITY 1000"));
  EXPECT_EQ(problems_of(minimal_ini() + "[SPINDLE_0]\nMIN_FORWARD_VELOCITY = 600\n"
                                        "MAX_REVERSE_VELOCITY = 500\n"),
            problem_at(44,
                       "[SPINDLE_0] MAX_REVERSE_VELOCITY: MIN_REVERSE_VELOCITY 600 (from "
                       "MIN_FORWARD_VELOCITY) must not be above MAX_REVERSE_VELOCITY 500"));
}

TEST_F(IoConfigTest, GpioSpindleNeedsAnOutputAChipAndABaseThread) {
  EXPECT_EQ(problems_of(minimal_ini() + "[SPINDLE_0]\nDRIVER = gpio\n"),
            (std::vector<std::string>{
                at(43) + ": [SPINDLE_0] DRIVER: DRIVER = gpio needs ENABLE or PWM (a gpio line)",
                at(43) + ": [SPINDLE_0] DRIVER: DRIVER = gpio needs [GPIO] CHIP (gpiochip0, or "
                         "vcd:FILE)"}));
  EXPECT_EQ(problems_of(minimal_ini() + chip() +
                        "[SPINDLE_0]\nDRIVER = gpio\nMAX_FORWARD_VELOCITY = 100\nPWM = 12\n"),
            problem_at(47,
                       "[SPINDLE_0] PWM: a gpio PWM output or encoder needs a base thread: set "
                       "[EMCMOT] BASE_PERIOD"));
  EXPECT_EQ(problems_of(gpio_ini(chip() + "[SPINDLE_0]\nDRIVER = gpio\nPWM = 12\n")),
            problem_at(kFirst + 4,
                       "[SPINDLE_0] PWM: PWM needs MAX_FORWARD_VELOCITY, the speed "
                       "at full duty cycle"));
  EXPECT_EQ(
      problems_of(gpio_ini(chip() + "[SPINDLE_0]\nDRIVER = gpio\nENABLE = modbus:0:1:coil:1\n")),
      problem_at(kFirst + 4,
                 "[SPINDLE_0] ENABLE: 'modbus:0:1:coil:1': DRIVER = gpio drives "
                 "gpio lines; write gpio:LINE (or sim:NAME)"));
  EXPECT_EQ(problems_of(gpio_ini(chip() + "[SPINDLE_0]\nDRIVER = gpio\nENABLE = gpio:\n")),
            (std::vector<std::string>{
                at(kFirst + 4) + ": [SPINDLE_0] ENABLE: 'gpio:': empty line",
            }));
}

TEST_F(IoConfigTest, EncoderChannelsComeTogetherWithPulsesPerRevolution) {
  const std::string head = chip() + "[SPINDLE_0]\nDRIVER = gpio\nENABLE = 4\n";
  EXPECT_EQ(problems_of(gpio_ini(head + "ENCODER_A = 5\n")),
            problem_at(kFirst + 5,
                       "[SPINDLE_0] ENCODER_A: ENCODER_A needs ENCODER_B: the "
                       "encoder has two channels"));
  EXPECT_EQ(problems_of(gpio_ini(head + "ENCODER_A = 5\nENCODER_B = 6\n")),
            problem_at(kFirst + 5,
                       "[SPINDLE_0] ENCODER_A: ENCODER_A and ENCODER_B need "
                       "ENCODER_PPR (pulses per revolution) above 0"));
  EXPECT_EQ(problems_of(gpio_ini(head + "ENCODER_INDEX = 7\n")),
            problem_at(kFirst + 5,
                       "[SPINDLE_0] ENCODER_INDEX: ENCODER_INDEX needs ENCODER_A and ENCODER_B"));
}

TEST_F(IoConfigTest, ModbusSpindleNeedsItsBus) {
  EXPECT_EQ(problems_of(minimal_ini() + "[SPINDLE_0]\nDRIVER = modbus\n"),
            problem_at(43,
                       "[SPINDLE_0] DRIVER: DRIVER = modbus needs MODBUS = n naming a "
                       "[MODBUS_n] section"));
  EXPECT_EQ(problems_of(minimal_ini() + "[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 2\n"),
            problem_at(44, "[SPINDLE_0] MODBUS: no section [MODBUS_2] in the file"));
  EXPECT_EQ(problems_of(minimal_ini() + "[MODBUS_0]\nHOST = x\n[SPINDLE_0]\nDRIVER = modbus\n"
                                        "MODBUS = 0\nCOMMAND_REGISTER = 1\n"),
            problem_at(47,
                       "[SPINDLE_0] COMMAND_REGISTER: COMMAND_REGISTER and SPEED_REGISTER "
                       "are both holding register 1"));
}

TEST_F(IoConfigTest, KeysOfAnotherDriverAreWarnedAboutAndIgnored) {
  const auto result = load(minimal_ini() +
                           "[SPINDLE_0]\nDRIVER = sim\nENABLE = gpio:17\nSLAVE = 3\n"
                           "HOME_SEQUENCE = 1\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(strings(result.warnings),
            (std::vector<std::string>{
                at(44) + ": [SPINDLE_0] ENABLE: ignored: a gpio key, and DRIVER is sim",
                at(45) + ": [SPINDLE_0] SLAVE: ignored: a modbus key, and DRIVER is sim"}));
  EXPECT_FALSE(result.config->spindle.enable.given());
  EXPECT_EQ(result.config->spindle.slave, 1);
}

TEST_F(IoConfigTest, OnlySpindleZeroIsDriven) {
  EXPECT_EQ(warnings_of(minimal_ini() + "[SPINDLE_1]\nMAX_FORWARD_VELOCITY = 100\n"),
            std::vector<std::string>{
                at(42) + ": [SPINDLE_1] cncd drives one spindle, [SPINDLE_0]; section ignored"});
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
                       "gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N or sim:NAME"));
  // Outside [SPINDLE_0] a bare line is not an address.
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nMIST_OUTPUT = 17\n"),
            problem_at(43,
                       "[CNCD] MIST_OUTPUT: '17': '17' names no kind; an address is "
                       "gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N or sim:NAME"));
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

}  // namespace
}  // namespace cncd::config::test
