// Signal addresses (gpio:, modbus:, sim:, ! for active low) as the INI gives them, and the
// table of every key: each value read, each bad one refused saying what is wrong.
#include <gtest/gtest.h>

#include <string>

#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

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
      "an address is gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N, sim:NAME or "
      "evdev:DEVICE:CODE";
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

}  // namespace
}  // namespace cncd::config::test
