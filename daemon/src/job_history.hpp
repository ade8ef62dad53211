// The job history kept off the task's thread: the runs' rows are written, and the history is
// read, on a thread of its own, so that a slow or full disk never holds up the task or the
// control socket. A row that cannot be written (a full disk) is kept in memory and written
// when the disk has room again; the problem is reported once, not at every try.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "job_store.hpp"
#include "task_outcome.hpp"

namespace cncd::daemon {

class JobHistory {
 public:
  // Rows kept in memory at the most while the database cannot be written.
  static constexpr std::size_t kMaxUnwritten = 1000;

  explicit JobHistory(std::filesystem::path path);
  ~JobHistory();
  JobHistory(const JobHistory&) = delete;
  JobHistory& operator=(const JobHistory&) = delete;

  // A run began: `job` as known at its start (its sha256 is worked out here from the
  // program). Returns the handle end() takes.
  std::uint64_t begin(JobRecord job);
  // The run ended: `job` has its end fields set (ended, result, error, cycle_s, parts).
  void end(std::uint64_t handle, const JobRecord& job);
  // jobs.history and jobs.stats: answered later under `token` (take()).
  void ask_history(std::uint64_t token, double since, int limit);
  void ask_stats(std::uint64_t token, double since);

  // The answers that are ready, and what went wrong or right again since the last call
  // (level, message) for the event log.
  std::vector<std::pair<std::uint64_t, TaskOutcome>> take();
  std::vector<std::pair<std::string, std::string>> take_reports();

 private:
  struct Ask {
    std::uint64_t token = 0;
    bool stats = false;
    double since = 0;
    int limit = 0;
  };
  struct Row {
    JobRecord job;
    bool inserted = false;  // its id is in the database
    bool ended = false;     // end() has come
    bool written = true;    // the database has it as it is now
    bool hashed = false;
  };

  void run();
  void write_rows(std::unique_lock<std::mutex>& lock);
  TaskOutcome answer(const Ask& ask);
  bool ensure_open();
  void report(const std::string& level, std::string message);

  std::filesystem::path path_;
  // The thread's only; open while it works, closed between (no file held open: the disk can
  // be remounted, the file moved).
  std::unique_ptr<JobStore> store_;
  bool marked_ = false;        // the runs a crash cut short have been marked
  std::string store_problem_;  // why the database is not open or written, "" when fine
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::uint64_t next_handle_ = 1;
  std::map<std::uint64_t, Row> rows_;  // not yet written for good
  std::deque<Ask> asks_;
  std::vector<std::pair<std::uint64_t, TaskOutcome>> answers_;
  std::vector<std::pair<std::string, std::string>> reports_;
  std::thread thread_;
};

// The SHA-256 of a regular file as 64 hex digits, or "" when it cannot be read.
std::string file_sha256(const std::filesystem::path& path);

}  // namespace cncd::daemon
