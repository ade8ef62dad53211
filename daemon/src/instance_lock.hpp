// One daemon per machine. Two cncd on one state directory would overwrite each other's
// offsets and positions; two on one Modbus bus would drive the same drives with opposite
// commands. At start the daemon locks its state directory (a "cncd.lock" file in it, and in
// the directory of each state file named by an absolute path) and each Modbus bus it uses
// (drivers::bus_lock_files), and holds the locks until it ends. GPIO lines need no lock of
// ours: the kernel lets one process at a time request a line.
#pragma once

#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/exclusive_lock.hpp"

namespace cncd::daemon {

struct InstanceLocks {
  std::vector<drivers::ExclusiveLock> held;
  // Buses left unlocked because their lock directory cannot be used, one line each.
  std::vector<std::string> warnings;
};

enum class LockVerdict {
  taken,
  busy,     // another process holds a lock: the message names its pid
  refused,  // the state directory cannot be made, is unsafe, or cannot be locked
};

// Makes the state directory when missing and takes every lock into `locks`. On busy or
// refused, `message` says which lock and why; the locks taken so far are released.
LockVerdict lock_instance(const config::MachineConfig& config, InstanceLocks& locks,
                          std::string& message,
                          const std::filesystem::path& bus_lock_dir = drivers::kBusLockDir);

}  // namespace cncd::daemon
