// One Modbus bus and the I/O thread that serves it (not installed). Every update period the
// thread writes each drive's latest setpoint and reads its position and status; it meets the
// servo thread only through seqlock mailboxes. No libmodbus call happens anywhere else.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/seqlock.hpp"
#include "cncd/drivers/spindle_position.hpp"

namespace cncd::drivers {

struct BusSettings {
  std::string section;  // "MODBUS_0", for messages
  int number = 0;       // n of [MODBUS_n]
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

enum class IoTable : std::uint8_t { coil, holding, discrete, input };

// A coil or register one of the machine's signals lives in.
struct IoPoint {
  enum class Signal : std::uint8_t {
    flood,
    mist,
    digital_out,
    analog_out,
    digital_in,
    analog_in,
    panel_in,       // index: config::PanelInput
    panel_counter,  // index: config::PanelCounter, a register of 16 bits that wraps
    panel_analog,   // index: config::PanelAnalog
    panel_light,    // index: config::PanelLight
  };
  Signal signal = Signal::flood;
  int index = 0;  // n of DIGITAL_OUTPUT_n and the like
  int slave = 1;
  IoTable table = IoTable::coil;
  int address = 0;
  bool output() const {
    return signal == Signal::flood || signal == Signal::mist || signal == Signal::digital_out ||
           signal == Signal::analog_out || signal == Signal::panel_light;
  }
};

struct IoSettings {
  std::vector<IoPoint> points;
  // The spindle VFD, when [SPINDLE_0] is a Modbus drive on this bus: its register profile is
  // the section's modbus keys.
  std::optional<config::SpindleConfig> vfd;
  bool empty() const { return points.empty() && !vfd; }
};

// Servo thread -> I/O thread: the latest outputs, and how many times the spindle was started
// (a new start forgets the VFD's last fault reason).
struct IoSetpoint {
  IoCommand command;
  std::uint32_t spindle_starts = 0;
};

// I/O thread -> servo thread.
struct IoReadback {
  std::uint32_t digital = 0;  // the bits of the digital inputs on this bus
  std::array<double, kMaxAnalogIo> analog{};
  std::uint64_t panel_inputs = 0;  // bit (1 << config::PanelInput)
  std::array<std::uint32_t, config::kPanelCounters> panel_counts{};  // registers: 0 .. 65535
  std::array<double, config::kPanelAnalogs> panel_analog{};
  double vfd_rpm = 0;            // actual speed, >= 0
  std::int64_t vfd_time_ns = 0;  // CLOCK_MONOTONIC of the VFD's last full answer; 0 = never
  std::uint16_t vfd_status = 0;
  bool vfd_fault = false;           // the fault bit, a refused reverse, or not running when told to
  SpindlePositionFit vfd_position;  // the shaft's motion at its last reading (valid: read)
  // The spindle command (SpindleCommand::sequence) written, or found already there, before
  // the reads of the VFD's last full answer.
  std::uint64_t vfd_acknowledged = 0;
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
  ModbusBus(BusSettings bus, std::vector<DriveSettings> drives, IoSettings io = {});
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
  // RT, servo thread (the only writer).
  void put_io(const IoSetpoint& setpoint) noexcept { io_setpoint_.store(setpoint); }
  // RT-safe, any thread. False while the I/O thread is publishing; keep the previous copy.
  bool get_io(IoReadback& out) const noexcept { return io_readback_.try_load(out); }
  // Why the spindle VFD faulted or went quiet (see ModbusBus::exchange_vfd).
  const FaultReason& vfd_reason() const noexcept { return vfd_reason_; }
  const IoSettings& io() const { return io_; }
  // How long a spindle command takes to reach the drive on average: half an update period in
  // the mailbox, and the request's bytes on an RTU line.
  std::int64_t command_delay_ns() const noexcept {
    return std::int64_t{bus_.update_period_ms} * 500'000 + request_ns_;
  }
  // Any thread: completed update cycles and their start time span, for rate figures.
  std::uint64_t cycles() const noexcept { return cycles_.load(std::memory_order_relaxed); }
  // Any thread: requests that failed (each try), and connects that failed.
  std::uint64_t errors() const noexcept { return errors_.load(std::memory_order_relaxed); }

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
  void exchange_io(bool connected);
  bool exchange_points(const IoCommand& command);
  bool exchange_vfd(const IoCommand& command);
  void vfd_problem(const char* format, ...) __attribute__((format(printf, 2, 3)));

  BusSettings bus_;
  std::vector<DriveSettings> drives_;
  std::unique_ptr<Seqlock<Setpoint>[]> setpoints_;
  std::unique_ptr<Seqlock<Readback>[]> readbacks_;
  std::vector<DriveState> state_;  // I/O thread only
  FaultReason reason_;
  IoSettings io_;
  Seqlock<IoSetpoint> io_setpoint_;
  Seqlock<IoReadback> io_readback_;
  // I/O thread only.
  IoSetpoint io_latest_{};
  IoReadback io_last_{};
  std::vector<double> point_written_;  // last value written to each output point, NaN = none
  int vfd_command_written_ = -1;       // -1 = not since the connection opened
  int vfd_speed_written_ = -1;
  std::int64_t vfd_run_since_ns_ = 0;  // when a run command was last written
  std::int64_t vfd_healthy_since_ns_ = 0;
  std::uint32_t vfd_starts_seen_ = 0;
  FaultReason vfd_reason_;
  SpindlePositionTracker vfd_position_;
  // The time a position request takes to reach the drive and its answer to come back (RTU:
  // their bytes on the line; TCP: 0).
  std::int64_t request_ns_ = 0;
  std::int64_t response_ns_ = 0;
  std::uint32_t reason_reset_ = 0;  // the reset request that last cleared reason_
  // A reset was asked for since reason_ was written: the next failure replaces it, and an
  // update with none clears it. Never emptied in between, so that the servo thread, reading it
  // on the stale feedback that follows the reset, still finds why.
  bool reason_outdated_ = false;
  void* ctx_ = nullptr;  // modbus_t*, I/O thread only once started
  bool link_failed_ = false;
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<std::uint64_t> errors_{0};
  void count_error() noexcept { errors_.fetch_add(1, std::memory_order_relaxed); }
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace cncd::drivers
