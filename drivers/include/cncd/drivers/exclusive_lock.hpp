// One cncd per machine: an advisory lock (flock) on a lock file, held as long as the object
// lives (the process's life for the daemon), released by the kernel however the process ends,
// so that a crash leaves no stale lock. The holder writes its pid into the file for whoever
// is refused next.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::drivers {

class ExclusiveLock {
 public:
  enum class Outcome { taken, busy, failed };

  ExclusiveLock() = default;
  ~ExclusiveLock();
  ExclusiveLock(ExclusiveLock&& other) noexcept;
  ExclusiveLock& operator=(ExclusiveLock&& other) noexcept;
  ExclusiveLock(const ExclusiveLock&) = delete;
  ExclusiveLock& operator=(const ExclusiveLock&) = delete;

  // Opens `file` (created mode 0644 when missing; never through a link) and locks it without
  // waiting. busy: another process holds it; holder() is its pid, or 0 when unknown. failed:
  // `error` says why (naming the file).
  Outcome take(const std::filesystem::path& file, std::string& error);
  pid_t holder() const { return holder_; }
  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
  pid_t holder_ = 0;
};

// Where cncd keeps the locks of shared buses: machine-wide, as serial lock files are.
inline constexpr const char* kBusLockDir = "/run/lock";

// The lock of each Modbus bus the machine uses ([JOINT_n] DRIVER = modbus, [SPINDLE_0]
// DRIVER = modbus, modbus: signals): a file in `lock_dir` named after the bus, "cncd-modbus-
// tcp-HOST-PORT.lock" (HOST as written) or "cncd-modbus-rtu-DEVICE.lock" (the device's real
// path, '/' as '_'), so that two daemons never drive the same drives whatever their INI or
// state directory. `what` names the bus for messages.
struct BusLockFile {
  std::string what;  // "[MODBUS_0] (tcp 127.0.0.1:502)"
  std::filesystem::path file;
};
std::vector<BusLockFile> bus_lock_files(const config::MachineConfig& machine,
                                        const std::filesystem::path& lock_dir = kBusLockDir);

}  // namespace cncd::drivers
