// Where program.open may read programs: regular files in the machine's program directories
// (MachineConfig::program_dirs) or below them, after resolving symlinks, so that a client
// cannot have cncd read (and quote in its errors) a file it may not read itself. Any thread.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace cncd::daemon {

struct ProgramFile {
  std::string path;   // the file, symlinks resolved; empty when refused
  std::string error;  // why it is refused, else empty
};

// `requested` is absolute or relative to the first program directory. A path outside the
// directories gets one message whether or not it exists; inside them the error says what is
// wrong (no such file, not a regular file, not readable).
ProgramFile find_program(const std::string& requested,
                         const std::vector<std::filesystem::path>& dirs);

}  // namespace cncd::daemon
