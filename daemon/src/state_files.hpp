// The state directory at start: created when missing, and each state file that is not there
// yet copied from its seed beside the INI (MachineConfig::*_seed), so that the machine starts
// from the configuration's shipped parameters and tools but never writes beside the INI.
#pragma once

#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::daemon {

struct StateNote {
  bool warning = false;  // a file that starts from the defaults; else a seed copied
  std::string text;
};

// Returns "" or what went wrong (naming the directory or file). `notes` gets one line for each
// seed copied and for each file that starts from the defaults because it does not exist.
std::string prepare_state_files(const config::MachineConfig& config, std::vector<StateNote>& notes);

}  // namespace cncd::daemon
