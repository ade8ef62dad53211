#include "start_checks.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <string>

#include "cncd/pipeline/startup_code.hpp"

namespace cncd::daemon {
namespace {

namespace fs = std::filesystem;

// "" when this process may create files in `dir`, else why not.
std::string cannot_write_in(const fs::path& dir) {
  if (::access(dir.c_str(), W_OK | X_OK) == 0) return "";
  return std::strerror(errno);
}

std::optional<std::string> state_directory_problem(const config::MachineConfig& config,
                                                   const fs::path& dir) {
  std::error_code ec;
  const std::string origin = " (" + config.cncd.state_dir_origin + ")";
  const std::string state = dir == config.cncd.state_dir
                                ? "the state directory '" + dir.string() + "'" + origin
                                : "'" + dir.string() + "' in the state directory" + origin;
  fs::path existing = dir;
  while (existing.has_relative_path() && !fs::exists(existing, ec))
    existing = existing.parent_path();
  if (!fs::is_directory(existing, ec)) {
    return "cannot create " + state + ": '" + existing.string() + "' is not a directory";
  }
  if (const std::string why = cannot_write_in(existing); !why.empty()) {
    return existing == dir
               ? state + " is not writable: " + why
               : "cannot create " + state + ": '" + existing.string() + "' is not writable: " + why;
  }
  return std::nullopt;
}

std::optional<std::string> fixed_directory_problem(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    return "directory '" + dir.string() +
           "' does not exist; cncd creates only the state directory, for files given by a "
           "relative path";
  }
  if (!fs::is_directory(dir, ec)) return "'" + dir.string() + "' is not a directory";
  if (const std::string why = cannot_write_in(dir); !why.empty()) {
    return "directory '" + dir.string() + "' is not writable: " + why;
  }
  return std::nullopt;
}

}  // namespace

std::vector<config::Problem> check_state_directories(const config::MachineConfig& config) {
  struct StateFile {
    const char* section;
    const char* key;
    const fs::path& file;
    const fs::path& seed;
  };
  const StateFile files[] = {
      {"RS274NGC", "PARAMETER_FILE", config.parameter_file, config.parameter_file_seed},
      {"EMCIO", "TOOL_TABLE", config.tool_table, config.tool_table_seed},
      {"TRAJ", "POSITION_FILE", config.position_file, config.position_file_seed},
  };
  std::vector<config::Problem> problems;
  for (const auto& f : files) {
    if (f.file.empty()) continue;
    std::error_code ec;
    std::optional<std::string> problem;
    if (fs::is_directory(f.file, ec)) {
      problem = "'" + f.file.string() + "' is a directory";
    } else if (!f.seed.empty()) {
      // A relative name: the file lives in the state directory, made at start when missing.
      problem = state_directory_problem(config, f.file.parent_path());
    } else {
      problem = fixed_directory_problem(f.file.parent_path());
    }
    if (problem) problems.push_back(pipeline::ini_problem(config, f.section, f.key, *problem));
  }
  return problems;
}

}  // namespace cncd::daemon
