#include "start_checks.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/startup_code.hpp"
#include "persist.hpp"

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
  // A directory yet to be made may sit in /tmp (sticky): only its own ownership counts then.
  if (auto unsafe = unsafe_state_directory(existing, existing != dir))
    return state + ": " + *unsafe;
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
  return unsafe_state_directory(dir, false);
}

}  // namespace

std::optional<std::string> unsafe_state_directory(const fs::path& dir, bool sticky_will_do) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) return std::nullopt;  // reported as missing elsewhere
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
  const bool sticky = (st.st_mode & S_ISVTX) != 0;
  if ((st.st_mode & S_IWOTH) != 0 && !(sticky && sticky_will_do)) {
    return "'" + dir.string() + "' can be written by every user (mode " + mode +
           "): another user could plant a link or a file of their own among the state files; "
           "remove that right (chmod o-w) or choose another directory";
  }
  if (!sticky_will_do && st.st_uid != ::geteuid() && st.st_uid != 0) {
    return "'" + dir.string() + "' belongs to uid " + std::to_string(st.st_uid) +
           ", neither cncd's user (uid " + std::to_string(::geteuid()) +
           ") nor root: its owner could replace the state files";
  }
  return std::nullopt;
}

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

std::vector<JointRange> joint_ranges(const config::MachineConfig& config) {
  std::vector<JointRange> ranges;
  for (const auto& joint : config.joints)
    ranges.push_back({joint.min_limit, joint.max_limit});
  return ranges;
}

std::vector<config::Problem> check_state_files(const config::MachineConfig& config) {
  std::vector<config::Problem> problems;
  // One interpreter a file, so that each refusal is reported at its own key.
  const auto refused = [&](const char* section, const char* key, bool parameters) {
    interp::InterpOptions options = pipeline::interpreter_options(config);
    options.parameter_file =
        parameters ? config::state_file_to_read(config.parameter_file, config.parameter_file_seed)
                   : "";
    options.tool_table =
        parameters ? "" : config::state_file_to_read(config.tool_table, config.tool_table_seed);
    const interp::Interpreter interp(options);
    if (const auto& error = interp.load_error()) {
      // The readers name the file and line themselves.
      problems.push_back(pipeline::ini_problem(
          config, section, key,
          error->message.rfind(error->file, 0) == 0 ? error->message : error->to_string()));
    }
  };
  if (!config.parameter_file.empty()) refused("RS274NGC", "PARAMETER_FILE", true);
  if (!config.tool_table.empty()) refused("EMCIO", "TOOL_TABLE", false);
  if (!config.position_file.empty()) {
    std::string error;
    const auto file = config::state_file_to_read(config.position_file, config.position_file_seed);
    if (!read_position_file(file, joint_ranges(config), error)) {
      problems.push_back(pipeline::ini_problem(config, "TRAJ", "POSITION_FILE", error));
    }
  }
  return problems;
}

}  // namespace cncd::daemon
