#include "instance_lock.hpp"

#include <algorithm>
#include <filesystem>

#include "start_checks.hpp"

namespace cncd::daemon {
namespace {

namespace fs = std::filesystem;

std::string holder_text(pid_t pid) {
  return pid > 0 ? "cncd pid " + std::to_string(pid) : "another process (its pid is unknown)";
}

// The directories that hold state files, the state directory first.
std::vector<fs::path> state_file_directories(const config::MachineConfig& config) {
  std::vector<fs::path> dirs;
  if (!config.cncd.state_dir.empty()) dirs.push_back(config.cncd.state_dir);
  const std::pair<const fs::path&, const fs::path&> files[] = {
      {config.parameter_file, config.parameter_file_seed},
      {config.tool_table, config.tool_table_seed},
      {config.position_file, config.position_file_seed},
  };
  for (const auto& [file, seed] : files) {
    // A file without a seed is named by an absolute path, outside the state directory.
    if (file.empty() || !seed.empty()) continue;
    if (std::find(dirs.begin(), dirs.end(), file.parent_path()) == dirs.end())
      dirs.push_back(file.parent_path());
  }
  return dirs;
}

}  // namespace

LockVerdict lock_instance(const config::MachineConfig& config, InstanceLocks& locks,
                          std::string& message, const fs::path& bus_lock_dir) {
  const auto give_up = [&](LockVerdict verdict, std::string why) {
    locks.held.clear();
    message = std::move(why);
    return verdict;
  };
  for (const fs::path& dir : state_file_directories(config)) {
    std::error_code ec;
    if (dir == config.cncd.state_dir && !fs::is_directory(dir, ec)) {
      // Created as the user cncd runs as, readable by others as LinuxCNC's config files are.
      fs::create_directories(dir, ec);
      if (ec) {
        return give_up(LockVerdict::refused,
                       "cannot create the state directory '" + dir.string() + "': " + ec.message());
      }
    }
    // Checked again now that it exists: someone else may have made it first.
    if (auto unsafe = unsafe_state_directory(dir, false)) {
      return give_up(LockVerdict::refused, "state directory: " + *unsafe);
    }
    drivers::ExclusiveLock lock;
    std::string error;
    const fs::path file = dir / "cncd.lock";
    switch (lock.take(file, error)) {
      case drivers::ExclusiveLock::Outcome::taken:
        locks.held.push_back(std::move(lock));
        break;
      case drivers::ExclusiveLock::Outcome::busy:
        return give_up(LockVerdict::busy, "the state directory '" + dir.string() +
                                              "' is in use by " + holder_text(lock.holder()) +
                                              " (lock file '" + file.string() +
                                              "'): one cncd a machine; stop that one first");
      case drivers::ExclusiveLock::Outcome::failed:
        return give_up(LockVerdict::refused, "cannot lock the state directory: " + error);
    }
  }
  for (const auto& bus : drivers::bus_lock_files(config, bus_lock_dir)) {
    drivers::ExclusiveLock lock;
    std::string error;
    switch (lock.take(bus.file, error)) {
      case drivers::ExclusiveLock::Outcome::taken:
        locks.held.push_back(std::move(lock));
        break;
      case drivers::ExclusiveLock::Outcome::busy:
        return give_up(LockVerdict::busy, bus.what + " is driven by " + holder_text(lock.holder()) +
                                              " (lock file '" + bus.file.string() +
                                              "'): one cncd a bus; stop that one first");
      case drivers::ExclusiveLock::Outcome::failed:
        // A system without a usable /run/lock still runs; the state directory's lock holds.
        locks.warnings.push_back(bus.what + " is not locked against another cncd: " + error);
        break;
    }
  }
  return LockVerdict::taken;
}

}  // namespace cncd::daemon
