#include "task.hpp"

#include <thread>

#include <spdlog/spdlog.h>

#include "cncd/drivers/driver.hpp"
#include "cncd/pipeline/machine.hpp"
#include "program_dirs.hpp"

namespace cncd::daemon {

using Clock = std::chrono::steady_clock;

// One interpreter for the daemon's life: like LinuxCNC's, its parameters and offsets carry
// from one program to the next.
Task::Task(const config::MachineConfig& config, EventLog& events, TaskAnswers& answers)
    : config_(config),
      events_(events),
      answers_(answers),
      motion_(config),
      interp_(std::make_unique<interp::Interpreter>(
          with_probe_writer(pipeline::interpreter_options(config), probe_writer_))),
      runner_(std::make_unique<pipeline::ProgramRunner>(
          *interp_, pipeline::machine_units(config),
          [&events](int line, const std::string& text) {
            events.add("info", "message", "line " + std::to_string(line) + ": " + text);
          },
          &config)),
      saved_tools_(interp_->tools()),
      saved_parameters_(interp_->persistent_parameters()),
      estimator_(config),
      opener_(config),
      previewer_(config) {
  program_dialect_ = interp_->dialect();  // before any program: the machine's
  runner_->feeder().on_warning([this](int line, const std::string& text) {
    const std::string where = mode_ == Mode::mdi ? std::string("MDI") : program_path_;
    events_.add("warning", "program", where + ":" + std::to_string(line) + ": " + text);
  });
}

Task::~Task() {
  shutdown();
}

std::string Task::start() {
  // The machine's parts, built here from the config and handed to motion.
  std::string error;
  auto drivers = drivers::make_drivers(config_, error);
  sim_ = nullptr;
  drivers_.clear();
  for (const auto& instance : drivers) {
    if (auto* sim = dynamic_cast<drivers::SimDriver*>(instance.driver.get()); sim != nullptr)
      sim_ = sim;
    drivers_.push_back(instance.driver.get());
  }
  if (error.empty()) error = motion_.start(std::move(drivers));
  started_ = error.empty();
  if (started_) mark_running();
  for (const auto& warning : motion_.start_warnings())
    events_.add("warning", "servo", warning);
  return error;
}

void Task::shutdown() {
  cancel_open("cncd is shutting down");
  if (exec_ != ExecState::idle) finish_program("aborted", "daemon shutting down");
  // Come to rest on the path before the drives go off, then keep the offsets.
  const auto status = motion_.status();
  if (status.motion != motion::MotionState::idle || status.queued != 0) {
    motion_.abort();
    const auto deadline = Clock::now() + std::chrono::seconds(5);
    while (motion_.status().motion != motion::MotionState::idle && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  motion_.machine_off();
  motion_.stop();
  drivers_.clear();
  sim_ = nullptr;
  if (files_corrupt_) return;
  // Also when nothing changed: a parameter file that did not exist yet is created.
  if (const auto error = interp_->save_parameters()) {
    events_.add("error", "parameters", error->to_string());
    spdlog::error("{}", error->to_string());
  }
  save_positions();
  started_ = false;
}

bool Task::all_homed(const motion::Status& status) const {
  for (int j = 0; j < status.joint_count; ++j) {
    if (!status.homed[static_cast<std::size_t>(j)]) return false;
  }
  return true;
}

void Task::run_program(int from_line, bool step) {
  if (opening_) {
    throw TaskError(
        TaskErrorKind::busy,
        "'" + opening_->path + "' is still being checked: run it once program.open has answered");
  }
  if (program_path_.empty()) throw TaskError(TaskErrorKind::program, "no program is open");
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program is already running");
  if (from_line < 0 || static_cast<std::uint64_t>(from_line) > program_lines_) {
    throw TaskError(TaskErrorKind::bad_value, "\"from_line\" must be from 1 to " +
                                                  std::to_string(program_lines_) +
                                                  ", the program's length");
  }
  const auto status = ready_status("running a program");
  refuse_if_door_open();
  // Checked again: a directory on the way may have been replaced by a symlink leading out.
  const ProgramFile file = find_program(program_path_, config_.program_dirs);
  tool_at_start_ = interp_->state().tool_in_spindle;
  if (!file.error.empty()) throw TaskError(TaskErrorKind::program, file.error);
  if (auto error = interp_->open(file.path, program_subs_)) {
    throw TaskError(TaskErrorKind::program, error->to_string());
  }
  // The file may have been changed since it was opened.
  program_dialect_ = interp_->dialect();
  start_run(Mode::automatic, status);
  runner_->skip_to(from_line, status.commanded, tool_at_start_,
                   pipeline::run_from_line_safe_z(config_));
  from_top_ = !runner_->skipping();
  run_from_line_ = from_top_ ? 0 : from_line;
  approach_done_s_.reset();
  stepping_ = step;
  runner_->single_step(step, 1);
  // Both clocks read now: `status` may be older (opening the program takes its time).
  started_at_ = Clock::now();
  started_cycles_ = motion_.status().rt.cycles;
  elapsed_s_ = 0;
  motion_s_ = 0;
  last_result_.clear();
  last_error_.clear();
  events_.add(
      "info", "program",
      program_path_ + (runner_->skipping() ? " started from line " + std::to_string(from_line)
                                           : std::string(" started")));
  begin_job();
  feed();
  // Ended in error before any of its moves reached the motion controller (the planner refused
  // the first one, the machine having been moved since the program was checked; a run from a
  // line the program never reaches): that is this request's answer, not a success.
  if (exec_ == ExecState::idle && last_result_ == "error" && runner_->moves_queued() == 0) {
    throw TaskError(TaskErrorKind::program, last_error_);
  }
}

motion::Status Task::ready_status(const char* before) const {
  auto status = motion_.status();
  if (status.machine != motion::MachineState::on)
    throw TaskError(TaskErrorKind::wrong_state, "machine is not on");
  if (status.motion != motion::MotionState::idle)
    throw TaskError(TaskErrorKind::busy, "the machine is moving");
  if (!config_.no_force_homing && !all_homed(status)) {
    throw TaskError(TaskErrorKind::not_homed,
                    std::string("all joints must be homed before ") + before);
  }
  return status;
}

void Task::mdi(const std::string& line, std::uint64_t token) {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI command is running");
  const auto status = ready_status("MDI");
  refuse_if_door_open();
  if (line.find('\n') != std::string::npos || line.size() > 4096) {
    throw TaskError(TaskErrorKind::bad_value,
                    "\"line\" must be one block of at most 4096 characters");
  }
  if (auto error = interp_->open_mdi(line)) {
    throw TaskError(TaskErrorKind::program, error->to_string());
  }
  start_run(Mode::mdi, status);
  mdi_token_ = token;
  feed();
}

void Task::start_run(Mode mode, const motion::Status& status) {
  // Under TCP (kept from the last MDI command) the program's position is the tool tip's.
  const motion::AxisPose at = runner_->program_start(status.commanded, mode == Mode::mdi);
  interp::Pose position{};
  std::copy(at.begin(), at.end(), position.begin());
  interp_->set_machine_position(position);
  runner_->start(&at, mode == Mode::mdi, interp_->state().tool_in_spindle);
  path_errors_base_ = status.path_errors;
  input_waits_seen_ = status.input_waits;
  probes_seen_ = status.probe.done;
  actions_done_base_ = status.actions_done;
  moves_done_base_ = status.moves_done;
  motion_.discard();
  mode_ = mode;
  paused_s_ = 0;
  set_exec(ExecState::running);
  stepping_ = false;
}

void Task::finish_program(const std::string& ended, const std::string& why, int line) {
  user_m_.stop();
  user_m_hold_ = 0;
  untake_tool_changes(ended == "done");
  // Offsets and tool data set by the program or MDI (G10, G92 ...) survive a crash or power
  // loss; those that cannot be saved are not kept, and the run says so.
  std::string result = ended;
  std::string error = why;
  if (const std::string unsaved = save_setup_files(); !unsaved.empty()) {
    const std::string text = "could not save the offsets or tools " +
                             std::string(mode_ == Mode::mdi ? "the block" : "the program") +
                             " set, so they are undone: " + unsaved;
    if (result == "done") {
      result = "error";
      error = text;
    } else {
      error += (error.empty() ? "" : "; ") + text;
    }
  }
  if (mode_ == Mode::mdi) {
    set_exec(ExecState::idle);
    mode_ = Mode::manual;
    if (result == "done") {
      answers_.post(mdi_token_, CommandDone{});
    } else if (ended == "done") {
      events_.add("error", "mdi", error);
      answers_.post(mdi_token_, TaskError(TaskErrorKind::save_failed, error));
    } else {
      events_.add(result == "error" ? "error" : "warning", "mdi",
                  error.empty() ? result : result + ": " + error);
      answers_.post(mdi_token_, TaskError(result == "error" ? TaskErrorKind::program
                                                            : TaskErrorKind::wrong_state,
                                          result + (error.empty() ? "" : ": " + error)));
    }
    mdi_token_ = 0;
    return;
  }
  set_exec(ExecState::idle);
  stepping_ = false;
  moves_completed_ = motion_.status().moves_done - moves_done_base_;
  elapsed_s_ = std::chrono::duration<double>(Clock::now() - started_at_).count();
  motion_s_ = servo_seconds_since(started_cycles_);
  last_result_ = result;
  last_error_ = error;
  end_job(result, error, line);
  if (result == "done") {
    events_.add("info", "program",
                fmt::format("{} finished in {:.3f} s", program_path_, elapsed_s_));
  } else {
    events_.add(result == "error" ? "error" : "warning", "program",
                fmt::format("{} {}{}", program_path_, result, error.empty() ? "" : ": " + error));
  }
}

void Task::feed() {
  // Bounded work per call keeps the control socket responsive: a run from a far line reads
  // every line before it, thousands a poll when they hardly move.
  pipeline::ProgramRunner::Budget budget;
  budget.max_blocks = 2000;
  budget.until = Clock::now() + std::chrono::milliseconds(2);
  if (runner_->advance(motion_, budget) == pipeline::ProgramRunner::Outcome::error) {
    motion_.abort();
    finish_with(runner_->error());
  }
}

void Task::finish_with(const pipeline::ProgramRunner::Error& error) {
  using Kind = pipeline::ProgramRunner::Error::Kind;
  const std::string where = mode_ == Mode::mdi ? std::string("MDI") : program_path_;
  switch (error.kind) {
    case Kind::interpreter:
      finish_program("error", error.interp ? error.interp->to_string() : error.message, error.line);
      return;
    case Kind::ends_before_line:
      finish_program("error", where + ": " + error.message);
      return;
    default:
      finish_program("error", where + ":" + std::to_string(error.line) + ": " + error.message,
                     error.line);
  }
}

void Task::poll() {
  drain_servo_events();
  user_m_.tick();
  poll_panel(motion_.status());
  if (opening_) {
    if (auto outcome = opener_.take()) finish_open(std::move(*outcome));
  }
  for (auto& [token, outcome] : previewer_.take())
    answers_.post(token, std::move(outcome));
  poll_jobs();
  const auto status = motion_.status();
  keep_positions(status);
  // An estop from the drives or an input, not machine.estop, cancels a pending open too.
  const bool in_estop = status.machine == motion::MachineState::estop;
  if (in_estop && !was_estop_) cancel_open("cancelled: the machine went into estop");
  was_estop_ = in_estop;
  // program.abort answers once the machine has come to rest.
  if (!abort_tokens_.empty() && status.motion == motion::MotionState::idle && status.queued == 0) {
    for (const auto token : abort_tokens_)
      answers_.post(token, CommandDone{});
    abort_tokens_.clear();
  }
  confirm_machine_on(status);
  poll_probe_file();
  if (exec_ == ExecState::idle) return;
  if (status.machine != motion::MachineState::on) {
    finish_program("aborted", status.fault_reason[0] != '\0' ? status.fault_reason
                                                             : "machine left the on state");
    return;
  }
  if (status.fault_reason[0] != '\0') {
    finish_program("error", status.fault_reason);
    return;
  }
  if (status.path_errors != path_errors_base_) {
    // The servo thread stopped the path (a spindle that did not reach its speed in time).
    motion_.abort();
    finish_program("error", (mode_ == Mode::mdi ? std::string("MDI") : program_path_) + ":" +
                                std::to_string(status.line) + ": " +
                                motion::format_event(status.path_error));
    return;
  }
  if (!poll_holds(status)) return;
  if (runner_->waiting_input() && status.input_waits > input_waits_seen_) {
    // The machine has waited for the M66: its answer is #5399 for the lines that follow.
    input_waits_seen_ = status.input_waits;
    interp_->set_input_result(status.input_result);
    runner_->input_done();
  }
  if (runner_->waiting_probe() && status.probe.done > probes_seen_ && status.queued == 0 &&
      status.motion == motion::MotionState::idle) {
    // The probing move is over: where it tripped goes to #5061-#5070, and the interpreter
    // reads on from where the machine stopped.
    probes_seen_ = status.probe.done;
    interp::Pose trip{};
    std::copy(status.probe.position.begin(), status.probe.position.end(), trip.begin());
    interp_->set_probe_result(trip, status.probe.tripped);
    interp::Pose at{};
    std::copy(status.commanded.begin(), status.commanded.end(), at.begin());
    interp_->set_machine_position(at);
    runner_->probe_done(status.commanded);
  }
  // Run from line: the remaining time counts from when the way to the line has ended.
  if (runner_->skipped_motion() && !runner_->skipping() && !approach_done_s_ &&
      status.moves_done - moves_done_base_ >= static_cast<std::uint64_t>(runner_->approach_moves()))
    approach_done_s_ = moving_s();
  if (exec_ == ExecState::paused) return;
  feed();
  if (exec_ != ExecState::running) return;
  // Counting completed moves (rather than looking at an empty queue) cannot mistake the instant
  // between enqueue and the servo thread picking a move up for the end of the program.
  const bool drained = runner_->drained() &&
                       status.moves_done - moves_done_base_ >= runner_->moves_queued() &&
                       status.actions_done - actions_done_base_ >= runner_->actions_queued() &&
                       status.motion == motion::MotionState::idle;
  if (!drained) return;
  if (runner_->stopped()) {
    // M0/M1/M60 reached: the machine has stopped at that point; resume continues.
    runner_->clear_stop();
    set_exec(ExecState::paused);
    events_.add("info", "program",
                fmt::format("stopped by M0/M1/M60 at line {}", interp_->current_line()));
    return;
  }
  if (runner_->ended()) {
    finish_program("done", "");
  } else if (stepping_ && runner_->step_over()) {
    set_exec(ExecState::paused);  // program.step: the line has been carried out
  }
}

bool Task::busy() const {
  return exec_ != ExecState::idle || opening_ || !on_tokens_.empty() ||
         motion_.status().motion != motion::MotionState::idle;
}

}  // namespace cncd::daemon
