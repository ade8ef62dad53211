#include "start_checks.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "cncd/config/ini_file.hpp"
#include "cncd/interp/interpreter.hpp"
#include "program_check.hpp"

namespace cncd::daemon {
namespace {

namespace fs = std::filesystem;

config::Problem problem_at(const config::MachineConfig& config, const char* section,
                           const char* key, std::string message) {
  config::SourceRef where{config.path.lexically_normal().string(), 0};
  if (config.ini) {
    if (const config::IniEntry* entry = config.ini->find(section, key)) where = entry->source;
  }
  return config::Problem{where.file, where.line, section, key, std::move(message)};
}

// Remembers the first command that moves an axis.
class MoveSink final : public interp::CanonSink {
 public:
  void emit(const interp::CanonCommand& command) override {
    if (first_ || (command.kind != interp::CanonKind::straight_traverse &&
                   command.kind != interp::CanonKind::straight_feed &&
                   command.kind != interp::CanonKind::arc_feed)) {
      return;
    }
    first_ = command.kind;
  }
  const std::optional<interp::CanonKind>& first() const { return first_; }

 private:
  std::optional<interp::CanonKind> first_;
};

const char* describe_move(interp::CanonKind kind) {
  switch (kind) {
    case interp::CanonKind::straight_traverse:
      return "a rapid move";
    case interp::CanonKind::arc_feed:
      return "an arc";
    default:
      return "a feed move";
  }
}

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

std::vector<config::Problem> check_startup_code(const config::MachineConfig& config) {
  std::vector<config::Problem> problems;
  if (config.startup_code.empty()) return problems;
  interp::InterpOptions options = interpreter_options(config);
  options.parameter_file =
      config::state_file_to_read(config.parameter_file, config.parameter_file_seed);
  options.tool_table = config::state_file_to_read(config.tool_table, config.tool_table_seed);
  auto interp = std::make_unique<interp::Interpreter>(options);
  if (interp->load_error()) {
    // A broken parameter file or tool table is reported when the daemon loads it; the
    // start-up code is judged on the defaults.
    options.parameter_file.clear();
    options.tool_table.clear();
    interp = std::make_unique<interp::Interpreter>(options);
  }
  MoveSink sink;
  std::optional<interp::InterpError> error = interp->open_string("M2\n", "start-up code");
  if (!error) error = interp::run_program(*interp, sink);
  const char* section = "RS274NGC";
  const char* key = "RS274NGC_STARTUP_CODE";
  if (error) {
    problems.push_back(problem_at(
        config, section, key,
        "the interpreter rejects it: " + error->message +
            (error->column > 0 ? " (column " + std::to_string(error->column) + ")" : "")));
  } else if (sink.first()) {
    problems.push_back(problem_at(
        config, section, key,
        std::string("it makes ") + describe_move(*sink.first()) +
            ", and it runs before every program and MDI command; set modes only (G17 G21 "
            "G40 G49 G54 G80 G90 G94 ...)"));
  }
  return problems;
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
    if (problem) problems.push_back(problem_at(config, f.section, f.key, *problem));
  }
  return problems;
}

}  // namespace cncd::daemon
