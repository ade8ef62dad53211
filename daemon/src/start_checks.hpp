// Checks of a loaded machine configuration that the config library cannot make: the state
// files need the host's file system (the start-up code, the interpreter: pipeline's
// check_startup_code). `cncd --check-config` and the daemon before it starts refuse a
// configuration with such a problem, reported at the INI key's line like a config problem.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "persist.hpp"

namespace cncd::daemon {

// The parameter file, tool table and position file must be writable where they are: a file in
// the state directory needs that directory, or the nearest existing directory above it (cncd
// creates the rest at start), to be writable by this process; a file named by an absolute
// path needs its directory to exist and be writable.
// Each directory must also be safe from other local users (unsafe_state_directory()).
std::vector<config::Problem> check_state_directories(const config::MachineConfig& config);

// Why another local user could tamper with the state files in `dir`, or nothing: `dir` is
// writable by every user (unless sticky and `sticky_will_do`: a directory like /tmp in which
// cncd is still to make its own), or, unless `sticky_will_do`, owned by a user other than
// cncd's or root. Nothing when `dir` does not exist.
std::optional<std::string> unsafe_state_directory(const std::filesystem::path& dir,
                                                  bool sticky_will_do);

// The parameter file, tool table and position file the daemon would read at start (the state
// file, else its seed), read as it reads them: a problem for each it would refuse, naming the
// file and line. Reads only, so that `cncd --check-config` refuses what the daemon refuses.
std::vector<config::Problem> check_state_files(const config::MachineConfig& config);

// Each joint's [JOINT_n] MIN_LIMIT and MAX_LIMIT, as a position file is checked against them.
std::vector<JointRange> joint_ranges(const config::MachineConfig& config);

}  // namespace cncd::daemon
