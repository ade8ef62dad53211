// A spindle VFD on loopback Modbus TCP for the driver tests, modelled from a register map
// alone: a small libmodbus server of its own (not cncd-drive-sim), so the driver is checked
// against the map and not against its own idea of it.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace cncd::test {

// What a drive's manual says about its registers.
struct VfdMap {
  int command_register = 0;  // holding
  int speed_register = 1;    // holding, the commanded speed in the drive's unit
  int actual_speed_register = 0;
  bool actual_speed_holding = false;  // else an input register
  int status_register = 1;
  bool status_holding = false;
  int command_stop = 0;
  int command_forward = 1;
  int command_reverse = 2;
  // Status bits; a Delta-style two-bit run state has its bit 0 and 1 both set when running.
  std::uint16_t running_bits = 1u << 0;
  std::uint16_t at_speed_bits = 1u << 1;  // 0: the drive has no at-speed bit
  std::uint16_t fault_bits = 1u << 2;
  std::uint16_t reverse_bits = 0;  // set while turning in reverse
  // A servo spindle's shaft: a counter of position_width bits (two registers for 32, high word
  // first) in input registers (holding with position_holding), counts_per_rev a revolution;
  // -1 = none. The motor then turns in real time at up to acceleration_rpm_s (0: at once), the
  // speed register in units_per_rpm. A drive without a position counter ramps alike when
  // acceleration_rpm_s is given (its at-speed bit set once the speed is reached).
  int position_register = -1;
  bool position_holding = false;
  int position_width = 32;
  double counts_per_rev = 4096;
  double units_per_rpm = 1;
  double acceleration_rpm_s = 0;
};

// A servo spindle: the generic profile with a 32-bit position counter at input register 10,
// 4096 counts a revolution, the speed in tens of rpm, ramping at 3000 rpm/s.
inline VfdMap servo_spindle_map() {
  VfdMap map;
  map.position_register = 10;
  map.counts_per_rev = 4096;
  map.units_per_rpm = 0.1;
  map.acceleration_rpm_s = 3000;
  return map;
}

class VfdServer {
 public:
  VfdServer(VfdMap map, int slave);
  ~VfdServer();
  VfdServer(const VfdServer&) = delete;
  VfdServer& operator=(const VfdServer&) = delete;

  // Listens on 127.0.0.1 at a free port and serves from a thread; "" or what went wrong.
  std::string start();
  int port() const { return port_; }

  std::uint16_t holding(int address);
  bool coil(int address);
  void set_input_register(int address, std::uint16_t value);
  void set_discrete_input(int address, bool on);
  // What a panel wired to the drive's spare registers and coils shows: a counter in a holding
  // register, a switch on a coil.
  void set_holding_register(int address, std::uint16_t value);
  void set_coil(int address, bool on);
  // How many write requests reached a coil or holding register.
  int writes(int address);
  // The drive trips (fault bits set, stops) or is healthy again.
  void set_fault(bool fault);
  // The drive stops answering (requests time out) or answers again.
  void set_silent(bool silent) { silent_.store(silent); }
  // Requests answered so far.
  int answered() const { return answered_.load(); }
  // The shaft's true position (revolutions, signed) at `now_ns` (CLOCK_MONOTONIC; up to 2 s
  // back), and its speed (rpm, signed) at `now_ns` (not before the last request), of a map with
  // a position register.
  double revolutions(std::int64_t now_ns);
  double rpm(std::int64_t now_ns);
  // Where the shaft came to rest or turned back, in order (revolutions; the first 64): what
  // a test reads of a move however late its own threads ran.
  std::vector<double> turning_points();
  // Each time an answer first showed the at-speed bit: when (CLOCK_MONOTONIC) and at what
  // speed (rpm, signed: negative in reverse).
  struct AtSpeed {
    std::int64_t time_ns = 0;
    double rpm = 0;
  };
  std::vector<AtSpeed> at_speed_log();

 private:
  void serve();
  void update_model();             // with mutex_ held
  void advance(std::int64_t now);  // the shaft, up to `now`; with mutex_ held
  // The motor ramps in real time (a position counter, or an acceleration given).
  bool ramps() const { return map_.position_register >= 0 || map_.acceleration_rpm_s > 0; }

  VfdMap map_;
  int slave_;
  void* ctx_ = nullptr;      // modbus_t*
  void* mapping_ = nullptr;  // modbus_mapping_t*
  int listen_fd_ = -1;
  int port_ = 0;
  std::mutex mutex_;
  std::map<int, int> writes_;
  bool fault_ = false;
  // The shaft (position maps).
  double target_rpm_ = 0;  // signed
  double rpm_ = 0;
  double revolutions_ = 0;
  std::int64_t model_ns_ = 0;  // 0: not yet started
  bool at_speed_ = false;      // the at-speed bit of the last update
  std::vector<AtSpeed> at_speed_log_;
  // Where the shaft was, every 100 us, for the last 2 s: a ring, newest at history_head_ - 1.
  struct Past {
    std::int64_t time_ns = 0;
    double revolutions = 0;
  };
  std::vector<Past> history_ = std::vector<Past>(20000);
  std::size_t history_head_ = 0;
  std::vector<double> turns_;
  std::size_t history_size_ = 0;
  std::atomic<bool> silent_{false};
  std::atomic<int> answered_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace cncd::test
