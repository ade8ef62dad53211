// The check of [RS274NGC] RS274NGC_STARTUP_CODE, which needs the interpreter: `cncd
// --check-config`, the daemon before it starts and cncd-check refuse a configuration whose
// start-up code the interpreter rejects or that moves an axis, reported at the INI key's line
// like a config problem.
#pragma once

#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::pipeline {

// The start-up code runs before every program and MDI session: a problem when the interpreter
// rejects it, or when it moves an axis (G0, G1, G2, G28 ...).
std::vector<config::Problem> check_startup_code(const config::MachineConfig& config);

// A problem at the line of `key` in `section` of the machine's INI (the INI itself when the
// key is not there).
config::Problem ini_problem(const config::MachineConfig& config, const char* section,
                            const char* key, std::string message);

}  // namespace cncd::pipeline
