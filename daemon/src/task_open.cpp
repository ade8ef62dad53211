// program.open: refused at once in the wrong state, else checked on the opener's worker and
// answered when the check ends (or is cancelled), while the loop goes on serving.
#include <spdlog/spdlog.h>

#include "cncd/pipeline/preview.hpp"
#include "cncd/pipeline/program_check.hpp"
#include "task.hpp"

namespace cncd::daemon {

void Task::open_program(const std::string& path, std::uint64_t token) {
  if (exec_ != ExecState::idle) throw TaskError(TaskErrorKind::busy, "a program is running");
  // The check runs from where the machine stands: a position still changing (or, homing,
  // not yet known) would give it a start the machine is not at.
  const auto status = motion_.status();
  switch (status.motion) {
    case motion::MotionState::idle:
      break;
    case motion::MotionState::jogging:
      throw TaskError(TaskErrorKind::busy,
                      "the machine is jogging: stop the jog, then open the program");
    case motion::MotionState::homing:
      throw TaskError(TaskErrorKind::busy,
                      "the machine is homing: open the program once homing has finished");
    default:
      throw TaskError(TaskErrorKind::busy,
                      "the machine is moving: open the program once it has stopped");
  }
  OpenRequest request;
  request.path = path;
  request.program_dirs = config_.program_dirs;
  request.interp = pipeline::interpreter_options(config_);
  std::copy(status.commanded.begin(), status.commanded.end(), request.start.begin());
  cancel_open("cancelled: replaced by a newer program.open of '" + path + "'");
  PendingOpen pending;
  pending.token = token;
  pending.path = path;
  pending.start = request.start;
  pending.job = opener_.start(std::move(request));
  opening_ = std::move(pending);
}

void Task::cancel_open(const std::string& why) {
  if (!opening_) return;
  opener_.cancel();
  answers_.post(opening_->token, TaskError(TaskErrorKind::cancelled,
                                           "program.open of '" + opening_->path + "' " + why));
  spdlog::info("program.open of '{}' {}", opening_->path, why);
  opening_.reset();
}

void Task::finish_open(OpenOutcome outcome) {
  if (!opening_ || outcome.job != opening_->job) return;
  const PendingOpen pending = std::move(*opening_);
  opening_.reset();
  for (const auto& warning : outcome.warnings)
    events_.add("warning", "program", warning);
  // program.run waits for the open; an MDI block does not.
  if (!outcome.error && exec_ != ExecState::idle) {
    outcome.error =
        TaskError(TaskErrorKind::busy, "an MDI command started while '" + pending.path +
                                           "' was checked: open it again once it has finished");
  }
  if (outcome.error) {
    answers_.post(pending.token, std::move(*outcome.error));
    return;
  }
  estimator_.start(outcome.path, pipeline::interpreter_options(config_), pending.start);
  previewer_.open(outcome.path, pipeline::interpreter_options(config_), pending.start);
  program_path_ = outcome.path;
  program_lines_ = outcome.lines;
  program_subs_ = std::move(outcome.subs);
  program_dialect_ = outcome.dialect;
  last_result_.clear();
  last_error_.clear();
  spdlog::info("program opened: {} ({} lines)", program_path_, program_lines_);
  answers_.post(pending.token, ProgramOpened{program_path_});
}

void Task::preview_program(double tolerance, std::uint64_t token) {
  if (tolerance <= 0) {
    tolerance =
        pipeline::default_preview_tolerance(config_.linear_units == config::LinearUnits::inch);
  }
  previewer_.request(tolerance, token);
}

}  // namespace cncd::daemon
