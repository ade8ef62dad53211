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
  motion_.resume();
  set_exec(ExecState::running);
}

void Task::abort(std::uint64_t token) {
  motion_.abort();
  if (exec_ != ExecState::idle) finish_program("aborted", "aborted by request");
  if (token != 0) abort_tokens_.push_back(token);
}

bool Task::skip_before_start(bool program_ended) {
  if (interp_->current_line() < skip_to_line_) {
    if (program_ended) {
      motion_.abort();
      finish_program("error", program_path_ + ": the program ends at line " +
                                  std::to_string(interp_->current_line()) + ", before line " +
                                  std::to_string(skip_to_line_));
      return false;
    }
    for (const auto& move : feeder_->pending) {
      if (move.kind == motion::Move::Kind::dwell || move.kind == motion::Move::Kind::action)
        continue;
      skip_end_ = move.end;
      skip_moved_ = true;
    }
    feeder_->pending.clear();
    feeder_->holds.clear();      // the tool changes and user M codes of the lines skipped
    feeder_->stop_seen = false;  // M0/M1 before the line do not stop a run from line
    return true;
  }
  if (skip_moved_) {
    motion::Move approach;
    approach.kind = motion::Move::Kind::traverse;
    approach.end = skip_end_;
    approach.line = interp_->current_line();
    feeder_->pending.push_front(approach);
  }
  // The spindle and coolant as the skipped lines left them, before the machine moves there.
  feeder_->restore_io_state();
  // A skipped M6 (or M61) left another tool in force than the one in the spindle: its length
  // is already in the line's positions, so the operator puts it in before anything moves.
  if (const int in_force = interp_->state().tool_in_spindle; in_force != tool_at_start_)
    feeder_->change_tool_first(in_force, interp_->current_line(), motion_.status().commanded,
                               tool_at_start_);
  skip_to_line_ = 0;
  return true;
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
  step_budget_ = 1;
  feed();
}

}  // namespace cncd::daemon
