// One Modbus bus and the I/O thread that serves it (not installed). Every update period the
// thread writes each drive's latest setpoint and reads its position and status; it meets the
// servo thread only through seqlock mailboxes. No libmodbus call happens anywhere else.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/seqlock.hpp"

namespace cncd::drivers {

struct BusSettings {
  std::string section;  // "MODBUS_0", for messages
  bool rtu = false;
  std::string host;
  int port = 502;
  std::string device;
  int baud = 19200;
  char parity = 'N';
  int data_bits = 8;
  int stop_bits = 1;
  int timeout_ms = 50;
  int update_period_ms = 10;
  int retries = 1;
  int rt_priority = 0;  // SCHED_FIFO priority of the I/O thread; 0: an ordinary thread
};

struct DriveSettings {
  int joint = 0;
  int slave = 1;
  int target_register = 0;
  int control_register = 2;
  int position_register = 0;
  int status_register = 2;
  bool wide = true;        // 32-bit positions in two registers
  bool high_first = true;  // word order of 32-bit positions
};

// Servo thread -> I/O thread.
struct Setpoint {
  std::int64_t counts = 0;
  std::uint32_t reset_request = 0;  // bumped on every rising edge of enable
  bool enable = false;
  std::uint64_t cycle = 0;  // the servo cycle that computed it (JointCommand::cycle)
};

// I/O thread -> servo thread.
struct Readback {
  std::int64_t counts = 0;
  std::int64_t time_ns = 0;  // CLOCK_MONOTONIC of the last good read; 0 = never
  // The commands the position answers (JointFeedback): the cycle of the setpoint written in
  // the exchange that read `counts` (just before the read), and of the newest one the drive
  // had been given an update period or more before the read (the oldest remembered when none
  // was). 0 before any setpoint was written.
  std::uint64_t command_cycle = 0;
  std::uint64_t previous_cycle = 0;
  std::uint32_t reset_ack = 0;
  std::uint16_t status = 0;
  bool fault = false;  // latched until a reset request is acknowledged
};

inline constexpr std::uint16_t kStatusReady = 1u << 0;
inline constexpr std::uint16_t kStatusEnabled = 1u << 1;
inline constexpr std::uint16_t kStatusFault = 1u << 2;
inline constexpr std::uint16_t kStatusInPosition = 1u << 3;
inline constexpr std::uint16_t kControlEnable = 1u << 0;
inline constexpr std::uint16_t kControlFaultReset = 1u << 1;

class ModbusBus {
 public:
  ModbusBus(BusSettings bus, std::vector<DriveSettings> drives);
  ~ModbusBus();
  ModbusBus(const ModbusBus&) = delete;
  ModbusBus& operator=(const ModbusBus&) = delete;

  // Non-RT.
  void start();
  void stop();
  const BusSettings& settings() const { return bus_; }
  std::size_t size() const { return drives_.size(); }

  // RT, servo thread (the only writer).
  void put_setpoint(std::size_t drive, const Setpoint& setpoint) noexcept {
    setpoints_[drive].store(setpoint);
  }
  // RT-safe, any thread. False while the I/O thread is publishing; keep the previous copy.
  bool get_readback(std::size_t drive, Readback& out) const noexcept {
    return readbacks_[drive].try_load(out);
  }
  const FaultReason& reason() const noexcept { return reason_; }
  // Any thread: completed update cycles and their start time span, for rate figures.
  std::uint64_t cycles() const noexcept { return cycles_.load(std::memory_order_relaxed); }

 private:
  struct DriveState {
    bool latched = false;
    bool pulse_reset = false;
    std::uint32_t reset_ack = 0;
    Setpoint setpoint{};  // the latest one loaded
    // The last setpoints the drive received, newest first: their cycle and when it first got
    // each (time 0: none).
    struct Written {
      std::uint64_t cycle = 0;
      std::int64_t time_ns = 0;
    };
    std::array<Written, 8> written{};
    Readback last{};
  };
  void loop();
  bool connect();
  void disconnect();
  bool exchange(std::size_t index, const Setpoint& setpoint);
  static void remember_write(DriveState& s, std::uint64_t cycle);
  void fail(std::size_t index, const char* what, int first, int count, bool drop_link);

  BusSettings bus_;
  std::vector<DriveSettings> drives_;
  std::unique_ptr<Seqlock<Setpoint>[]> setpoints_;
  std::unique_ptr<Seqlock<Readback>[]> readbacks_;
  std::vector<DriveState> state_;  // I/O thread only
  FaultReason reason_;
  std::uint32_t reason_reset_ = 0;  // the reset request that last cleared reason_
  void* ctx_ = nullptr;             // modbus_t*, I/O thread only once started
  bool link_failed_ = false;
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace cncd::drivers
