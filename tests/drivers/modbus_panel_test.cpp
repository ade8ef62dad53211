// The panel's `modbus:` signals against a libmodbus server on loopback: buttons and switches on
// discrete inputs and coils, an MPG counter in a holding register (16 bits, wrapping), an
// analog knob in an input register, and lights on coils, all through the bus's I/O thread.
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "modbus_io_fixture.hpp"

namespace cncd::test {
namespace {

using config::PanelAnalog;
using config::PanelCounter;
using config::PanelInput;
using config::PanelLight;
using drivers::IoCommand;
using Table = config::SignalAddress::Table;

constexpr std::uint64_t bit(PanelInput which) {
  return std::uint64_t{1} << static_cast<int>(which);
}

class ModbusPanel : public ModbusIo {
 protected:
  void start_panel() {
    start(VfdMap{}, [](config::MachineConfig& c) {
      c.panel.present = true;
      c.panel.inputs[static_cast<std::size_t>(PanelInput::cycle_start)] =
          modbus(Table::discrete, 40);
      c.panel.inputs[static_cast<std::size_t>(PanelInput::single_block)] = modbus(Table::coil, 41);
      c.panel.inputs[static_cast<std::size_t>(PanelInput::jog_minus_x) + 1] =
          modbus(Table::discrete, 42);
      c.panel.mpg.counts = modbus(Table::holding, 50);
      c.panel.knobs[static_cast<std::size_t>(PanelAnalog::feed_override)].analog =
          modbus(Table::input, 51);
      c.panel.knobs[static_cast<std::size_t>(PanelAnalog::spindle_override)].encoder.counts =
          modbus(Table::input, 52);
      c.panel.lights[static_cast<std::size_t>(PanelLight::green)] = modbus(Table::coil, 60);
      c.panel.lights[static_cast<std::size_t>(PanelLight::lamp_feed_hold)] =
          modbus(Table::coil, 61);
    });
  }
  std::uint32_t mpg() const {
    return feedback_.panel.counts[static_cast<std::size_t>(PanelCounter::mpg)];
  }
};

TEST_F(ModbusPanel, ButtonsAndSwitchesComeFromDiscreteInputsAndCoils) {
  start_panel();
  const std::uint64_t jog_minus_y = std::uint64_t{1}
                                    << (static_cast<int>(PanelInput::jog_minus_x) + 1);
  server_->set_discrete_input(40, true);
  server_->set_coil(41, true);
  ASSERT_TRUE(servo_until(IoCommand{},
                          [&] {
                            return feedback_.panel.inputs ==
                                   (bit(PanelInput::cycle_start) | bit(PanelInput::single_block));
                          }))
      << feedback_.panel.inputs << " " << reason();
  server_->set_discrete_input(40, false);
  server_->set_discrete_input(42, true);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] {
    return feedback_.panel.inputs == (bit(PanelInput::single_block) | jog_minus_y);
  })) << feedback_.panel.inputs;
}

// A 16-bit register wraps from 65535 to 0; the driver says so with counter_bits 16, so that
// the servo thread unwraps it into one more count, not 65535 fewer.
TEST_F(ModbusPanel, ARegisterCounterWrapsAtSixteenBits) {
  start_panel();
  server_->set_holding_register(50, 65534);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] { return mpg() == 65534; })) << reason();
  EXPECT_EQ(feedback_.panel.counter_bits[static_cast<std::size_t>(PanelCounter::mpg)], 16);
  EXPECT_EQ(feedback_.panel.counter_bits[static_cast<std::size_t>(PanelCounter::feed_override)], 0);
  EXPECT_EQ(feedback_.panel.counter_bits[static_cast<std::size_t>(PanelCounter::spindle_override)],
            16);
  server_->set_holding_register(50, 65535);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] { return mpg() == 65535; }));
  server_->set_holding_register(50, 0);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] { return mpg() == 0; }));
  server_->set_input_register(52, 7);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] {
    return feedback_.panel.counts[static_cast<std::size_t>(PanelCounter::spindle_override)] == 7;
  }));
}

TEST_F(ModbusPanel, AnAnalogKnobComesFromARegister) {
  start_panel();
  server_->set_input_register(51, 500);
  ASSERT_TRUE(servo_until(IoCommand{}, [&] {
    return feedback_.panel.analog[static_cast<std::size_t>(PanelAnalog::feed_override)] == 500;
  })) << reason();
}

TEST_F(ModbusPanel, LightsGoToCoils) {
  start_panel();
  IoCommand c;
  c.panel = 1u << static_cast<int>(PanelLight::green);
  ASSERT_TRUE(servo_until(c, [&] { return server_->coil(60) && !server_->coil(61); })) << reason();
  const int green_writes = server_->writes(60);
  c.panel = 1u << static_cast<int>(PanelLight::lamp_feed_hold);
  ASSERT_TRUE(servo_until(c, [&] { return !server_->coil(60) && server_->coil(61); }));
  EXPECT_EQ(server_->writes(60), green_writes + 1) << "written on change only";
}

TEST_F(ModbusPanel, CountersOnBitsAndEncoderLinesAreRefused) {
  loaded_ = load_machine(dir_, 1, "", "[MODBUS_0]\nHOST = 127.0.0.1\nPORT = 1\n");
  ASSERT_TRUE(loaded_.ok());
  config::MachineConfig c = *loaded_.config;
  c.panel.mpg.counts = modbus(Table::coil, 3);
  std::string error = driver_.configure(c, {});
  EXPECT_NE(error.find("a coil or discrete input holds no count"), std::string::npos) << error;
  c.panel.mpg = {};
  c.panel.knobs[0].encoder.a = modbus(Table::discrete, 1);
  c.panel.knobs[0].encoder.b = modbus(Table::discrete, 2);
  error = drivers::ModbusDriver{}.configure(c, {});
  EXPECT_NE(error.find("wire its counter to FEED_OVERRIDE_COUNTS"), std::string::npos) << error;
  c.panel.knobs[0].encoder = {};
  c.panel.lights[0] = modbus(Table::discrete, 4);
  error = drivers::ModbusDriver{}.configure(c, {});
  EXPECT_NE(error.find("read-only"), std::string::npos) << error;
}

}  // namespace
}  // namespace cncd::test
