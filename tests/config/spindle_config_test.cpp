// [SPINDLE_0] for each driver (gpio, modbus, sim): each key read, limits as LinuxCNC gives them,
// each bad value refused at its FILE:LINE, and keys of another driver warned about.
#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

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

}  // namespace
}  // namespace cncd::config::test
