#include "state_files.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "persist.hpp"

namespace cncd::daemon {
namespace {

struct StateFile {
  const char* what;
  const std::filesystem::path& file;
  const std::filesystem::path& seed;
  const char* when_missing;
};

std::string make_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  if (std::filesystem::is_directory(dir, ec)) return "";
  // Created as the user cncd runs as, readable by others as LinuxCNC's config files are.
  std::filesystem::create_directories(dir, ec);
  if (ec) return "cannot create the state directory '" + dir.string() + "': " + ec.message();
  return "";
}

std::string copy_seed(const StateFile& f) {
  std::ifstream in(f.seed, std::ios::binary);
  if (!in) return "cannot read '" + f.seed.string() + "': " + std::strerror(errno);
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) return "cannot read '" + f.seed.string() + "'";
  return atomic_write_file(f.file, content.str());
}

}  // namespace

std::string prepare_state_files(const config::MachineConfig& config,
                                std::vector<StateNote>& notes) {
  const StateFile files[] = {
      {"parameter file", config.parameter_file, config.parameter_file_seed,
       "default parameters are used, and the file is written when they change and on shutdown"},
      {"tool table", config.tool_table, config.tool_table_seed,
       "the table is empty until a tool is set"},
      {"position file", config.position_file, config.position_file_seed,
       "the joints start at 0, and the file is written as the machine moves and on shutdown"},
  };
  for (const auto& f : files) {
    if (f.file.empty()) continue;
    std::error_code ec;
    if (std::filesystem::exists(f.file, ec)) continue;
    if (ec)
      return "cannot look at the " + std::string(f.what) + " '" + f.file.string() +
             "': " + ec.message();
    // Only the state directory is made here: a directory named by an absolute path in the INI
    // is the administrator's to create.
    if (!config.cncd.state_dir.empty() && !f.seed.empty()) {
      if (auto error = make_directory(f.file.parent_path()); !error.empty()) return error;
    }
    if (!f.seed.empty() && std::filesystem::exists(f.seed, ec)) {
      if (auto error = copy_seed(f); !error.empty()) return error;
      notes.push_back({false, std::string(f.what) + " '" + f.file.string() +
                                  "' starts as a copy of '" + f.seed.string() + "'"});
      continue;
    }
    notes.push_back({true, std::string(f.what) + " '" + f.file.string() +
                               "' does not exist: " + f.when_missing});
  }
  return "";
}

}  // namespace cncd::daemon
