// Holding, resuming and aborting a run, and running a program other than from the top: run
// from line and single steps.
#include "task.hpp"

namespace cncd::daemon {

PauseWaitReport Task::pause() {
  if (exec_ != ExecState::running)
    throw TaskError(TaskErrorKind::wrong_state, "no program is running");
  motion_.pause();
  set_exec(ExecState::paused);
  // As the servo thread last published: a synchronized move under way then runs to its end.
  const auto status = motion_.status();
  return pause_wait_report(status.sync, status.line);
}

void Task::resume() {
  if (exec_ != ExecState::paused)
    throw TaskError(TaskErrorKind::wrong_state, "the program is not paused");
  refuse_if_door_open();
  stepping_ = false;
  runner_->single_step(false, 0);
  motion_.resume();
  set_exec(ExecState::running);
}

void Task::abort(std::uint64_t token) {
  motion_.abort();
  if (exec_ != ExecState::idle) finish_program("aborted", "aborted by request");
  if (token != 0) abort_tokens_.push_back(token);
}

void Task::step() {
  if (exec_ == ExecState::running) {
    throw TaskError(TaskErrorKind::busy, mode_ == Mode::mdi ? "an MDI command is running"
                                         : stepping_        ? "the last step is still running"
                                                            : "the program is running");
  }
  if (exec_ == ExecState::idle) {
    run_program(0, true);
    return;
  }
  refuse_if_door_open();
  motion_.resume();
  set_exec(ExecState::running);
  stepping_ = true;
  runner_->single_step(true, 1);
  feed();
}

}  // namespace cncd::daemon
