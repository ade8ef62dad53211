#include "cncd/pipeline/startup_code.hpp"

#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "cncd/config/ini_file.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {
namespace {

// Remembers the first command that moves an axis, as "a rapid move", "a feed move", "an arc".
class MoveSink final : public interp::CanonSink {
 public:
  void emit(const interp::CanonCommand& command) override {
    if (first_) return;
    first_ = std::visit(interp::Overloaded{
                            [](const interp::StraightTraverse&) { return "a rapid move"; },
                            [](const interp::StraightFeed&) { return "a feed move"; },
                            [](const interp::ArcFeed&) { return "an arc"; },
                            [](const interp::NurbsFeed&) { return "a spline"; },
                            [](const auto&) { return static_cast<const char*>(nullptr); },
                        },
                        command.op);
  }
  const char* first() const { return first_; }

 private:
  const char* first_ = nullptr;
};

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
        std::string("it makes ") + sink.first() +
            ", and it runs before every program and MDI command; set modes only (G17 G21 "
            "G40 G49 G54 G80 G90 G94 ...)"));
  }
  return problems;
}

}  // namespace cncd::pipeline
