// Signals and the spindle VFD of the modbus driver over loopback TCP, against VfdServer: a
// drive modelled from its register map (the generic profile, a Delta VFD-E, an
// AutomationDirect GS2), with coils, registers and discrete inputs beside it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "modbus_io_fixture.hpp"

namespace cncd::test {
namespace {

using drivers::IoCommand;
using drivers::IoFeedback;
using Table = config::SignalAddress::Table;

config::SpindleConfig generic_spindle() {
  config::SpindleConfig s;
  s.present = true;
  s.driver = config::SpindleDriver::modbus;
  s.modbus = 0;
  s.slave = kSlave;
  s.max_forward_velocity = 24000;
  s.speed_scale = 0.1;  // the drive takes tens of rpm
  return s;             // the rest: the default profile
}

TEST_F(ModbusIo, GenericVfdRunsForwardReverseAndStops) {
  start_vfd(VfdMap{}, generic_spindle());
  ASSERT_TRUE(servo_until(spindle(true, false, 1200), [&] {
    return feedback_.spindle.at_speed && server_->holding(0) == 1;
  })) << reason();
  EXPECT_EQ(server_->holding(1), 120);
  EXPECT_TRUE(feedback_.spindle.present);
  EXPECT_TRUE(feedback_.spindle.has_at_speed);
  EXPECT_FALSE(feedback_.spindle.has_position);
  EXPECT_DOUBLE_EQ(feedback_.spindle.rpm, 1200);
  EXPECT_FALSE(feedback_.spindle.fault || feedback_.spindle.stale) << reason();
  EXPECT_EQ(reason(), "");

  ASSERT_TRUE(servo_until(spindle(true, true, 1200), [&] { return server_->holding(0) == 2; }));
  ASSERT_TRUE(servo_until(spindle(false, true, 1200),
                          [&] { return server_->holding(0) == 0 && feedback_.spindle.rpm == 0; }));
  EXPECT_FALSE(feedback_.spindle.at_speed);
  // Written once at start (stopped, speed 0), then on every change only: speed 0 and 120,
  // command 0, 1, 2 and 0.
  servo(spindle(false, true, 1200), 50);
  EXPECT_EQ(server_->writes(1), 2);
  EXPECT_EQ(server_->writes(0), 4);
}

// Each reading says which spindle command the VFD had been written before it was read: the
// first one after M4 S800 to a VFD turning forward at 1350 rpm shows its at-speed bit off, and
// none before it claims the new command.
TEST_F(ModbusIo, AVfdReadingAcknowledgesTheCommandWrittenBeforeIt) {
  VfdMap map;
  map.units_per_rpm = 0.1;
  map.acceleration_rpm_s = 3000;
  start_vfd(map, generic_spindle());
  IoCommand forward = spindle(true, false, 1350);
  forward.spindle.sequence = 1;
  ASSERT_TRUE(servo_until(forward, [&] {
    return feedback_.spindle.acknowledged == 1 && feedback_.spindle.at_speed;
  })) << reason();
  IoCommand reverse = spindle(true, true, 800);
  reverse.spindle.sequence = 2;
  bool first = true;
  ASSERT_TRUE(servo_until(reverse, [&] {
    if (feedback_.spindle.acknowledged < 2) return false;
    if (first) {
      first = false;
      // The registers had the command before the reading was taken.
      EXPECT_EQ(server_->holding(0), 2);
      EXPECT_EQ(server_->holding(1), 80);
      EXPECT_FALSE(feedback_.spindle.at_speed);
    }
    return feedback_.spindle.at_speed;
  })) << reason();
  EXPECT_FALSE(first);
  const auto log = server_->at_speed_log();
  ASSERT_EQ(log.size(), 2u);
  EXPECT_DOUBLE_EQ(log[1].rpm, -800);
}

TEST_F(ModbusIo, AServoSpindlesPositionIsFollowedBetweenReadings) {
  // A servo spindle with a 16-bit position counter (it wraps every 16 revolutions), read every
  // 5 ms, ramping at 3000 rpm/s: up to 600 rpm, over to -600 and back to rest. Each servo
  // period the driver's position is compared with the shaft's true one at that moment.
  VfdMap map = servo_spindle_map();
  map.position_width = 16;
  auto s = generic_spindle();
  s.position_register = 10;
  s.position_width = 16;
  s.position_scale = 4096;
  s.acceleration = 3000;
  start_vfd(map, s);
  std::vector<double> errors;
  double lowest = 0;
  double highest = 0;
  const auto run = [&](const IoCommand& command, int ms) {
    for (int i = 0; i < ms; ++i) {
      driver_.write_io(command);
      feedback_ = IoFeedback{};
      driver_.read_io(feedback_);
      ASSERT_TRUE(feedback_.spindle.has_position);
      // The shaft where it truly was at the moment the driver gave its position for.
      ASSERT_NE(feedback_.spindle.time_ns, 0);
      const double truth = server_->revolutions(feedback_.spindle.time_ns);
      errors.push_back(std::abs(feedback_.spindle.revolutions - truth));
      lowest = std::min(lowest, truth);
      highest = std::max(highest, truth);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };
  ASSERT_TRUE(servo_until(spindle(false, false, 0), [&] { return feedback_.spindle.has_position; }))
      << reason();
  run(spindle(true, false, 600), 1200);
  run(spindle(true, true, 600), 1800);
  run(spindle(false, false, 0), 500);
  EXPECT_EQ(reason(), "");
  // It went round both ways, past the counter's wrap.
  EXPECT_GT(highest, 5);
  EXPECT_LT(lowest, -1);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  const double p95 = errors[errors.size() * 95 / 100];
  std::printf(
      "position error over %zu periods: median %.5f, 95th percentile %.5f, largest %.5f "
      "rev\n",
      errors.size(), median, p95, errors.back());
  // At 10 rev/s the last reading itself is up to 5 ms (0.05 rev) old: the prediction is what
  // keeps the position within a thread's tolerance (0.02 of a pitch).
  // Taking the last reading as the position: median 0.023, 95th percentile 0.052.
  EXPECT_LE(median, 0.003);
  EXPECT_LE(p95, 0.015);
}

TEST_F(ModbusIo, SpeedIsRoundedAndClampedToARegister) {
  auto s = generic_spindle();
  s.speed_scale = 1.0 / 6.0;
  start_vfd(VfdMap{}, s);
  ASSERT_TRUE(servo_until(spindle(true, false, 1000), [&] { return server_->holding(1) == 167; }))
      << server_->holding(1);
  ASSERT_TRUE(servo_until(spindle(true, false, 1e9), [&] { return server_->holding(1) == 65535; }));
}

TEST_F(ModbusIo, TheFaultBitIsAFaultWithAReason) {
  start_vfd(VfdMap{}, generic_spindle());
  ASSERT_TRUE(servo_until(spindle(true, false, 1200), [&] { return feedback_.spindle.at_speed; }));
  server_->set_fault(true);
  ASSERT_TRUE(servo_until(spindle(true, false, 1200), [&] { return feedback_.spindle.fault; }));
  EXPECT_EQ(reason(), "modbus bus 0 slave 3 (spindle VFD): reports a fault (status 0x0004)");
  EXPECT_FALSE(feedback_.spindle.stale);
  // Cleared at the drive and started again: healthy, and the reason is gone.
  server_->set_fault(false);
  servo(spindle(false, false, 0), 20);
  ASSERT_TRUE(servo_until(spindle(true, false, 1200),
                          [&] { return feedback_.spindle.at_speed && !feedback_.spindle.fault; }));
  EXPECT_EQ(reason(), "");
}

TEST_F(ModbusIo, ASilentVfdGoesStaleWithAReason) {
  start_vfd(VfdMap{}, generic_spindle());
  ASSERT_TRUE(servo_until(spindle(true, false, 1200), [&] { return feedback_.spindle.at_speed; }));
  EXPECT_FALSE(feedback_.spindle.stale);
  server_->set_silent(true);
  ASSERT_TRUE(servo_until(spindle(true, false, 1200), [&] { return feedback_.spindle.stale; }));
  EXPECT_EQ(reason(), "modbus bus 0 slave 3 (spindle VFD): no answer (timeout)");
  server_->set_silent(false);
  EXPECT_TRUE(servo_until(spindle(true, false, 1200), [&] { return !feedback_.spindle.stale; }));
}

TEST_F(ModbusIo, CoilsAndRegistersCarryTheSignals) {
  start(VfdMap{}, [](config::MachineConfig& c) {
    c.io.flood = modbus(Table::coil, 5);
    c.io.mist = modbus(Table::holding, 20);
    c.io.digital_outputs[1] = modbus(Table::coil, 6);
    c.io.analog_outputs[0] = modbus(Table::holding, 10);
    c.io.analog_outputs[15] = modbus(Table::holding, 11);
    c.io.digital_inputs[2] = modbus(Table::discrete, 3);
    c.io.digital_inputs[4] = modbus(Table::input, 7);
    c.io.analog_inputs[1] = modbus(Table::input, 8);
  });
  IoCommand c;
  c.flood = true;
  c.digital = 1u << 1;
  c.analog[0] = 12.5;   // half away from zero
  c.analog[15] = -2.4;  // two's complement
  server_->set_discrete_input(3, true);
  server_->set_input_register(7, 9);
  server_->set_input_register(8, 4321);
  ASSERT_TRUE(servo_until(c, [&] {
    return server_->coil(5) && server_->coil(6) && server_->holding(10) == 13 &&
           server_->holding(11) == 65534 && feedback_.analog[1] == 4321 &&
           feedback_.digital == ((1u << 2) | (1u << 4));
  })) << feedback_.digital;
  EXPECT_EQ(server_->holding(20), 0);
  EXPECT_GE(server_->writes(20), 1);  // mist off, written all the same
  EXPECT_FALSE(feedback_.spindle.present);
  // Unchanged outputs are not written again. (The bus may have written them once already,
  // all off, before the first command arrived.)
  const int flood_writes = server_->writes(5);
  const int dout_writes = server_->writes(6);
  const int analog_writes = server_->writes(10);
  servo(c, 50);
  EXPECT_EQ(server_->writes(5), flood_writes);
  EXPECT_EQ(server_->writes(10), analog_writes);
  c.flood = false;
  c.mist = true;
  server_->set_discrete_input(3, false);
  ASSERT_TRUE(servo_until(c, [&] {
    return !server_->coil(5) && server_->holding(20) == 1 && feedback_.digital == (1u << 4);
  }));
  EXPECT_EQ(server_->writes(5), flood_writes + 1);
  EXPECT_EQ(server_->writes(6), dout_writes);
}

TEST_F(ModbusIo, OutputsOnReadOnlyTablesAreRefused) {
  loaded_ = load_machine(dir_, 1, "", "[MODBUS_0]\nHOST = 127.0.0.1\nPORT = 1\n");
  ASSERT_TRUE(loaded_.ok());
  auto c = *loaded_.config;
  c.io.flood = modbus(Table::discrete, 1);
  EXPECT_NE(driver_.configure(c, {}).find("read-only"), std::string::npos);
  c.io.flood = {};
  c.io.digital_outputs[0] = modbus(Table::coil, 1);
  c.io.digital_outputs[0].bus = 4;
  EXPECT_NE(driver_.configure(c, {}).find("[MODBUS_4]"), std::string::npos);
}

// Delta VFD-E (config/examples/modbus_delta_vfd_e.ini): command word 0x2000 (bits 1-0: 01
// stop, 10 run; bits 5-4: 01 forward, 10 reverse), frequency 0x2001 in 0.01 Hz, status
// 0x2101 (bits 1-0: 11 running; bits 4-3: 11 reverse) and output frequency 0x2103, both
// holding registers; no at-speed or fault bit.
VfdMap delta_vfd_e_map() {
  VfdMap m;
  m.command_register = 0x2000;
  m.speed_register = 0x2001;
  m.actual_speed_register = 0x2103;
  m.actual_speed_holding = true;
  m.status_register = 0x2101;
  m.status_holding = true;
  m.command_stop = 0x0001;
  m.command_forward = 0x0012;
  m.command_reverse = 0x0022;
  m.running_bits = 0x0003;
  m.at_speed_bits = 0;
  m.fault_bits = 0;
  m.reverse_bits = 0x0018;
  return m;
}

config::SpindleConfig delta_vfd_e_spindle() {
  config::SpindleConfig s = generic_spindle();
  s.speed_scale = 100.0 / 60.0;  // 2-pole: rpm / 60 = Hz, in 0.01 Hz
  s.command_register = 0x2000;
  s.speed_register = 0x2001;
  s.actual_speed_register = 0x2103;
  s.status_register = 0x2101;
  s.actual_speed_table = Table::holding;
  s.status_table = Table::holding;
  s.command_stop = 0x0001;
  s.command_forward = 0x0012;
  s.command_reverse = 0x0022;
  s.running_bit = 1;
  s.at_speed_bit = -1;
  s.fault_bit = -1;
  return s;
}

TEST_F(ModbusIo, DeltaVfdEProfile) {
  start_vfd(delta_vfd_e_map(), delta_vfd_e_spindle());
  ASSERT_TRUE(servo_until(spindle(true, false, 12000), [&] {
    return server_->holding(0x2000) == 0x12 && feedback_.spindle.rpm > 11999;
  })) << reason();
  EXPECT_EQ(server_->holding(0x2001), 20000);  // 200.00 Hz
  EXPECT_NEAR(feedback_.spindle.rpm, 12000, 0.01);
  EXPECT_FALSE(feedback_.spindle.has_at_speed);
  EXPECT_FALSE(feedback_.spindle.fault || feedback_.spindle.stale) << reason();
  ASSERT_TRUE(servo_until(spindle(true, true, 6000), [&] {
    return server_->holding(0x2000) == 0x22 && server_->holding(0x2001) == 10000;
  }));
  ASSERT_TRUE(servo_until(spindle(false, true, 6000), [&] {
    return server_->holding(0x2000) == 0x01 && feedback_.spindle.rpm == 0;
  }));
  EXPECT_FALSE(feedback_.spindle.fault) << reason();
}

TEST_F(ModbusIo, DeltaVfdETrippedWhileRunningIsAFault) {
  start_vfd(delta_vfd_e_map(), delta_vfd_e_spindle());
  ASSERT_TRUE(servo_until(spindle(true, false, 12000), [&] { return feedback_.spindle.rpm > 0; }));
  server_->set_fault(true);  // the drive trips: it stops, its run bits clear
  ASSERT_TRUE(servo_until(
      spindle(true, false, 12000), [&] { return feedback_.spindle.fault; }, 3000));
  EXPECT_EQ(reason(),
            "modbus bus 0 slave 3 (spindle VFD): not running although told to (status 0x0000)");
}

// AutomationDirect GS2 (config/examples/modbus_gs2.ini): P9.26 speed reference 0x091A in
// 0.1 Hz, P9.27 run command 0x091B (0 stop, 1 run), direction in P9.28 (not written: the
// profile has one command register, so it runs forward only), status monitor 2 at 0x2101 and
// output frequency at 0x2103 in 0.1 Hz.
VfdMap gs2_map() {
  VfdMap m;
  m.command_register = 0x091B;
  m.speed_register = 0x091A;
  m.actual_speed_register = 0x2103;
  m.actual_speed_holding = true;
  m.status_register = 0x2101;
  m.status_holding = true;
  m.command_stop = 0;
  m.command_forward = 1;
  m.command_reverse = -1;  // no such command
  m.running_bits = 0x0003;
  m.at_speed_bits = 0;
  m.fault_bits = 0;
  return m;
}

TEST_F(ModbusIo, Gs2ProfileRunsForwardAndRefusesReverse) {
  config::SpindleConfig s = generic_spindle();
  s.speed_scale = 10.0 / 60.0;  // 2-pole: rpm / 60 = Hz, in 0.1 Hz
  s.command_register = 0x091B;
  s.speed_register = 0x091A;
  s.actual_speed_register = 0x2103;
  s.status_register = 0x2101;
  s.actual_speed_table = Table::holding;
  s.status_table = Table::holding;
  s.command_stop = 0;
  s.command_forward = 1;
  s.command_reverse = 0;  // = COMMAND_STOP: no reverse
  s.running_bit = 1;
  s.at_speed_bit = -1;
  s.fault_bit = -1;
  start_vfd(gs2_map(), s);
  ASSERT_TRUE(servo_until(spindle(true, false, 18000), [&] {
    return server_->holding(0x091B) == 1 && feedback_.spindle.rpm > 17999;
  })) << reason();
  EXPECT_EQ(server_->holding(0x091A), 3000);  // 300.0 Hz
  EXPECT_NEAR(feedback_.spindle.rpm, 18000, 0.01);
  EXPECT_FALSE(feedback_.spindle.fault || feedback_.spindle.stale) << reason();
  ASSERT_TRUE(servo_until(spindle(true, true, 18000), [&] { return feedback_.spindle.fault; }));
  EXPECT_EQ(server_->holding(0x091B), 0);  // stopped, not turned forward
  EXPECT_NE(reason().find("no reverse"), std::string::npos) << reason();
}

}  // namespace
}  // namespace cncd::test
