// Checks of a loaded machine configuration that the config library cannot make: the state
// files need the host's file system (the start-up code, the interpreter: pipeline's
// check_startup_code). `cncd --check-config` and the daemon before it starts refuse a
// configuration with such a problem, reported at the INI key's line like a config problem.
#pragma once

#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::daemon {

// The parameter file, tool table and position file must be writable where they are: a file in
// the state directory needs that directory, or the nearest existing directory above it (cncd
// creates the rest at start), to be writable by this process; a file named by an absolute
// path needs its directory to exist and be writable.
std::vector<config::Problem> check_state_directories(const config::MachineConfig& config);

}  // namespace cncd::daemon
