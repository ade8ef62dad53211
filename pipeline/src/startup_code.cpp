#include "cncd/pipeline/startup_code.hpp"

#include <memory>
#include <optional>
#include <string>

#include "cncd/config/ini_file.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {
namespace {

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

}  // namespace

config::Problem ini_problem(const config::MachineConfig& config, const char* section,
                            const char* key, std::string message) {
  config::SourceRef where{config.path.lexically_normal().string(), 0};
  if (config.ini) {
    if (const config::IniEntry* entry = config.ini->find(section, key)) where = entry->source;
  }
  return config::Problem{where.file, where.line, section, key, std::move(message)};
}

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
    problems.push_back(ini_problem(
        config, section, key,
        "the interpreter rejects it: " + error->message +
            (error->column > 0 ? " (column " + std::to_string(error->column) + ")" : "")));
  } else if (sink.first()) {
    problems.push_back(ini_problem(
        config, section, key,
        std::string("it makes ") + describe_move(*sink.first()) +
            ", and it runs before every program and MDI command; set modes only (G17 G21 "
            "G40 G49 G54 G80 G90 G94 ...)"));
  }
  return problems;
}

}  // namespace cncd::pipeline
