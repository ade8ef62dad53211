// The job history: one row a program run, in an SQLite database in the state directory
// (WAL mode, so that a crash of the daemon, even kill -9, leaves it whole). A run is written
// when it starts, as "running", and again when it ends; a run still "running" when the
// database is opened again was cut short by the daemon's end and is marked "interrupted".
// Not thread-safe: one thread (JobHistory's) uses it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;

namespace cncd::daemon {

struct JobRecord {
  std::int64_t id = 0;  // set by insert()
  std::string program;
  std::string sha256;  // of the program file as the run began; "" when it could not be read
  double started = 0;  // seconds since the Unix epoch
  std::optional<double> ended;
  std::string result = "running";  // running | done | aborted | error | interrupted
  int error_line = 0;              // 0: none
  std::string error;
  std::optional<double> cycle_s;  // on the servo clock
  std::optional<double> estimate_s;
  int parts = 0;
  std::string started_by;  // the event log's name for who asked, "" when unknown
  int from_line = 0;       // 0: from the top
};

// Calls `f(name, field)` for each field of `job` (a JobRecord, const or not), in the order of
// the jobs table's columns, which is also the order of the store's SQL statements: the one
// list that the store's writes and reads and the job history's JSON go by.
template <class Record, class F>
void for_each_job_field(Record& job, F&& f) {
  f("id", job.id);
  f("program", job.program);
  f("sha256", job.sha256);
  f("started", job.started);
  f("ended", job.ended);
  f("result", job.result);
  f("error_line", job.error_line);
  f("error", job.error);
  f("cycle_s", job.cycle_s);
  f("estimate_s", job.estimate_s);
  f("parts", job.parts);
  f("started_by", job.started_by);
  f("from_line", job.from_line);
}

struct JobStats {
  std::map<std::string, std::int64_t> by_result;  // result -> jobs
  std::int64_t jobs = 0;
  std::int64_t parts = 0;
  double cycle_s = 0;       // summed over the runs that ended
  double done_cycle_s = 0;  // summed over the runs that ended "done"
  std::int64_t last_id = 0;
};

class JobStore {
 public:
  // Opens or creates the database; null and `error` what went wrong, naming the file. With
  // `mark_interrupted`, the runs left "running" are marked "interrupted" (interrupted()).
  static std::unique_ptr<JobStore> open(const std::filesystem::path& path, bool mark_interrupted,
                                        std::string& error);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  // How many runs open() found cut short and marked "interrupted".
  int interrupted() const { return interrupted_; }
  // Each returns "" or what went wrong (SQLite's words, naming the file).
  std::string insert(JobRecord& job);
  std::string finish(const JobRecord& job);
  // Runs started at or after `since` (Unix seconds), the newest `limit`, newest first.
  std::string history(double since, int limit, std::vector<JobRecord>& out);
  std::string stats(double since, JobStats& out);

 private:
  JobStore(sqlite3* db, std::filesystem::path path) : db_(db), path_(std::move(path)) {}
  std::string exec(const char* sql);
  std::string failure(const char* what) const;

  sqlite3* db_;
  std::filesystem::path path_;
  int interrupted_ = 0;
};

}  // namespace cncd::daemon
