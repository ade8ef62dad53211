// A simulated Modbus servo drive (or several) implementing cncd's default register profile:
//   holding 0-1  target position, signed 32-bit counts, high word first
//   holding 2    control word: bit 0 enable, bit 1 fault reset
//   input 0-1    actual position, signed 32-bit counts, high word first
//   input 2      status word: bit 0 ready, bit 1 enabled, bit 2 fault, bit 3 in position
// The actual position follows the target through a first-order lag while enabled. Serves
// Modbus TCP on a loopback port, or RTU on a pseudo-terminal it creates. Used by the
// cncd-drive-sim executable and, in-process, by tests.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

namespace cncd::drivers {

struct DriveSimOptions {
  bool rtu = false;
  std::string address = "127.0.0.1";  // tcp
  int port = 0;                       // tcp; 0 = any free port (see DriveSim::port())
  int first_slave = 1;
  int drives = 1;       // unit ids first_slave .. first_slave + drives - 1 (tcp; rtu serves one)
  double lag_s = 0.01;  // following time constant; 0 = the actual position is the target
  std::int32_t in_position_counts = 2;
  // SCHED_FIFO priority of the serving threads, as a drive has a processor of its own and is
  // not kept waiting by the host's other work; 0: ordinary threads. Where the system refuses,
  // start() still serves and warning() says so.
  int rt_priority = 0;
};

inline constexpr int kDriveSimMaxDrives = 16;

class DriveSim {
 public:
  explicit DriveSim(DriveSimOptions options);
  ~DriveSim();
  DriveSim(const DriveSim&) = delete;
  DriveSim& operator=(const DriveSim&) = delete;

  // Binds (tcp) or creates the pseudo-terminal (rtu) and starts serving; "" or an error.
  std::string start();
  // Stops serving and closes every connection, as a drive that lost power.
  void stop();
  int port() const { return port_; }
  // rtu: the terminal a client opens (DEVICE = ...).
  const std::string& device() const { return device_; }
  // Why the threads run at ordinary priority although rt_priority asked otherwise; "" if not.
  std::string warning() const;

  // Any thread. Fault injection: the drive sets its fault bit (and disables) until cleared
  // here and reset by the master; silent: requests get no reply (timeouts); exception: every
  // request gets an "illegal data address" exception reply.
  void set_fault(int slave, bool fault) noexcept;
  void set_silent(bool silent) noexcept { silent_.store(silent); }
  void set_exception(bool exception) noexcept { exception_.store(exception); }
  void set_lag(double lag_s) noexcept { lag_s_.store(lag_s); }

  // Any thread: the drive's registers as last seen.
  std::int32_t target(int slave) const noexcept;
  std::int32_t actual(int slave) const noexcept;
  std::uint16_t control(int slave) const noexcept;
  std::uint16_t status(int slave) const noexcept;
  // Requests that wrote the target registers.
  std::uint64_t target_writes(int slave) const noexcept;

 private:
  struct Drive {
    std::atomic<std::int32_t> target{0};
    std::atomic<std::int32_t> actual{0};
    std::atomic<std::uint16_t> control{0};
    std::atomic<std::uint16_t> status{0};
    std::atomic<std::uint64_t> target_writes{0};
    std::atomic<bool> injected_fault{false};
    bool fault = false;   // server thread
    double position = 0;  // server thread, counts
  };
  Drive* drive(int slave) noexcept;
  const Drive* drive(int slave) const noexcept;
  // `field` of the drive at `slave`; 0 when there is none.
  template <typename T>
  T load(int slave, const std::atomic<T> Drive::*field) const noexcept {
    const Drive* d = drive(slave);
    return d != nullptr ? (d->*field).load() : T{};
  }
  void serve_tcp();
  void serve_rtu();
  void relay();
  void advance(double dt) noexcept;
  void raise_priority(std::thread& thread) noexcept;
  int handle(void* ctx, const std::uint8_t* query, int length);

  DriveSimOptions options_;
  std::array<Drive, kDriveSimMaxDrives> drives_{};
  std::atomic<double> lag_s_;
  std::atomic<bool> silent_{false};
  std::atomic<bool> exception_{false};
  std::atomic<bool> running_{false};
  int priority_error_ = 0;  // errno of the last refused SCHED_FIFO request (start())
  void* ctx_ = nullptr;
  void* mapping_ = nullptr;
  int listen_fd_ = -1;
  int port_ = 0;
  int master_a_ = -1;  // rtu: pty pair bridged like a null-modem cable
  int master_b_ = -1;
  std::string device_;
  std::string server_device_;
  std::thread thread_;
  std::thread relay_thread_;
};

}  // namespace cncd::drivers
