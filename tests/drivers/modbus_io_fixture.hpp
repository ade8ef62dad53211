// The modbus driver with no joints against a VfdServer on loopback TCP, played by a test that
// stands in for the servo thread: the fixture of the signal, spindle and panel tests.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "test_util.hpp"
#include "vfd_server.hpp"

namespace cncd::test {

inline constexpr int kSlave = 3;

inline config::SignalAddress modbus(config::SignalAddress::Table table, int address) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::modbus;
  a.bus = 0;
  a.slave = kSlave;
  a.table = table;
  a.address = address;
  a.text = "modbus:0:3:" + std::to_string(address);
  return a;
}

inline drivers::IoCommand spindle(bool enable, bool reverse, double rpm) {
  drivers::IoCommand c;
  c.spindle = drivers::SpindleCommand{enable, reverse, rpm};
  return c;
}

class ModbusIo : public ::testing::Test {
 protected:
  // Starts the server with `map`, then the driver with no joints and the spindle and
  // signals `setup` arranges.
  template <typename Setup>
  void start(const VfdMap& map, Setup setup) {
    server_ = std::make_unique<VfdServer>(map, kSlave);
    ASSERT_EQ(server_->start(), "");
    loaded_ = load_machine(
        dir_, 1, "",
        "[MODBUS_0]\nTRANSPORT = tcp\nHOST = 127.0.0.1\nPORT = " + std::to_string(server_->port()) +
            "\nTIMEOUT_MS = 40\nUPDATE_PERIOD_MS = 5\nRETRIES = 1\n");
    ASSERT_TRUE(loaded_.ok());
    config::MachineConfig c = *loaded_.config;
    setup(c);
    ASSERT_EQ(driver_.configure(c, {}), "");
    driver_.enable();
  }
  void start_vfd(const VfdMap& map, const config::SpindleConfig& spindle) {
    start(map, [&](config::MachineConfig& c) { c.spindle = spindle; });
  }
  void TearDown() override { driver_.disable(); }

  // Plays the servo thread at 1 ms until `done` holds, for at most `ms` periods.
  template <typename Done>
  bool servo_until(const drivers::IoCommand& command, Done done, int ms = 2000) {
    for (int i = 0; i < ms; ++i) {
      driver_.write_io(command);
      feedback_ = drivers::IoFeedback{};
      driver_.read_io(feedback_);
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  }
  void servo(const drivers::IoCommand& command, int ms) {
    servo_until(
        command, [] { return false; }, ms);
  }
  std::string reason() const {
    char text[drivers::kFaultReasonSize];
    driver_.fault_reason(text, sizeof text);
    return text;
  }

  TempDir dir_;
  config::LoadResult loaded_;
  std::unique_ptr<VfdServer> server_;
  drivers::ModbusDriver driver_;
  drivers::IoFeedback feedback_;
};

}  // namespace cncd::test
