// Checks of a loaded machine configuration that the config library cannot make: the start-up
// code needs the interpreter, the state files need the host's file system. `cncd
// --check-config`, the daemon before it starts, and cncd-check (the start-up code only) refuse
// a configuration with such a problem, reported at the INI key's line like a config problem.
#pragma once

#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::daemon {

// [RS274NGC] RS274NGC_STARTUP_CODE runs before every program and MDI session: a problem when
// the interpreter rejects it, or when it moves an axis (G0, G1, G2, G28 ...).
std::vector<config::Problem> check_startup_code(const config::MachineConfig& config);

// The parameter file, tool table and position file must be writable where they are: a file in
// the state directory needs that directory, or the nearest existing directory above it (cncd
// creates the rest at start), to be writable by this process; a file named by an absolute
// path needs its directory to exist and be writable.
std::vector<config::Problem> check_state_directories(const config::MachineConfig& config);

}  // namespace cncd::daemon
