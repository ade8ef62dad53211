// program.open's long work, off the daemon's loop: the interpreter and soft-limit check of the
// whole program (check_program) and indexing its lines and subroutines run on a worker thread of
// their own, so that estop, jog.stop, pause and abort are answered at once however long the check
// takes. start(), cancel() and take() are called on the loop thread. The worker shares nothing the
// loop changes: it gets a copy of what it needs in OpenRequest, reads the machine
// configuration (never changed after loading), builds its own interpreter and hands back an
// OpenOutcome.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"
#include "task_outcome.hpp"
#include "worker_thread.hpp"

namespace cncd::daemon {

struct OpenRequest {
  std::string path;                                 // as the client gave it
  std::vector<std::filesystem::path> program_dirs;  // MachineConfig::program_dirs
  interp::InterpOptions interp;
  // Where the machine stood when program.open arrived (machine coordinates and units): the
  // check starts there.
  interp::Pose start{};
};

struct OpenOutcome {
  std::uint64_t job = 0;
  std::optional<TaskError> error;  // none: the program passed and may be opened
  std::string path;                // the program file, symlinks resolved
  std::uint64_t lines = 0;
  // Its subroutine definitions: a run's calls go straight to them, never reading the program
  // forward on the daemon's loop.
  std::shared_ptr<const interp::SubroutineIndex> subs;
  interp::Dialect dialect = interp::Dialect::linuxcnc;  // the one the program is read in
  // For the event log: the check stopped before the program's end (its time budget).
  std::vector<std::string> warnings;
};

class ProgramOpener {
 public:
  // A program that takes longer than this to check (processor time) is opened with a warning
  // (the planner still checks each move as it runs); the client waits for its answer.
  static constexpr double kMaxCheckSeconds = 5;

  explicit ProgramOpener(const config::MachineConfig& machine);
  ~ProgramOpener();
  ProgramOpener(const ProgramOpener&) = delete;
  ProgramOpener& operator=(const ProgramOpener&) = delete;

  // Starts checking for an open and returns the job's number; the check of an earlier job
  // is cancelled and its outcome never comes. Never waits for the worker.
  std::uint64_t start(OpenRequest request);
  // Cancels the job under way, if any; never waits for the worker.
  void cancel();
  // The outcome of the last job started, once it is there (taken once).
  std::optional<OpenOutcome> take();

 private:
  void work(WorkerThread::Lock& lock);

  const config::MachineConfig& machine_;
  // Guarded by worker_.mutex():
  std::optional<std::pair<std::uint64_t, OpenRequest>> next_;
  std::optional<OpenOutcome> done_;
  std::uint64_t wanted_ = 0;  // the job whose outcome is wanted, 0 = none
  // Stops the check under way; cleared by the worker when it takes the next job.
  std::atomic<bool> cancel_{false};
  std::uint64_t last_job_ = 0;  // loop thread only
  WorkerThread worker_;
};

}  // namespace cncd::daemon
