// program.preview's work, off the daemon's loop: the open program's toolpath
// (pipeline::preview_program, the check of program.open with its path collected) is worked out
// on a thread of its own at a lower CPU priority and kept, serialized, for the last few
// tolerances asked for, until another program is opened. open(), request() and take() are
// called on the loop thread and never wait for the worker; the worker shares nothing the loop
// changes but its queue and its results, under a lock.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"
#include "task_outcome.hpp"
#include "worker_thread.hpp"

namespace cncd::daemon {

class ProgramPreviewer {
 public:
  // Previews kept per open program, and tolerances waited for at once.
  static constexpr std::size_t kCached = 4;
  static constexpr std::size_t kMaxWaiting = 4;
  // Processor time a preview may take; past it the preview drawn so far is answered, saying
  // where it stopped.
  static constexpr double kMaxSeconds = 60;

  explicit ProgramPreviewer(const config::MachineConfig& machine);
  ~ProgramPreviewer();
  ProgramPreviewer(const ProgramPreviewer&) = delete;
  ProgramPreviewer& operator=(const ProgramPreviewer&) = delete;

  // The program open from now on, read as its open check read it; forgets the previews kept
  // and cancels those under way (their requests are answered with an error).
  void open(const std::filesystem::path& program, const interp::InterpOptions& options,
            const interp::Pose& start);
  // The open program's preview at `tolerance` (machine units) for the request under `token`:
  // answered through take(), at once when it is kept. Throws TaskError when no program is open
  // or too many other tolerances are waited for.
  void request(double tolerance, std::uint64_t token);
  // The answers that are ready: a serialized preview (RawResult) or an error.
  std::vector<std::pair<std::uint64_t, TaskOutcome>> take();

 private:
  struct Job {
    std::uint64_t generation = 0;
    double tolerance = 0;
  };
  struct Done {
    std::uint64_t generation = 0;
    double tolerance = 0;
    std::shared_ptr<const std::string> json;
  };
  void work(WorkerThread::Lock& lock);

  const config::MachineConfig& machine_;
  // Loop thread only:
  std::map<double, std::vector<std::uint64_t>> waiting_;
  std::vector<std::pair<double, std::shared_ptr<const std::string>>> cached_;  // newest last
  std::vector<std::pair<std::uint64_t, TaskOutcome>> ready_;
  bool has_program_ = false;
  // Guarded by worker_.mutex():
  std::uint64_t generation_ = 0;
  std::filesystem::path program_;
  interp::InterpOptions options_;
  interp::Pose start_{};
  std::deque<Job> jobs_;
  std::vector<Done> done_;
  // Stops the preview under way when the program changes or the daemon stops.
  std::atomic<bool> cancel_{false};
  WorkerThread worker_;
};

}  // namespace cncd::daemon
