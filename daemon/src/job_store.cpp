#include "job_store.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cstring>
#include <system_error>
#include <utility>

namespace cncd::daemon {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS jobs(
  id INTEGER PRIMARY KEY,
  program TEXT NOT NULL,
  sha256 TEXT NOT NULL,
  started REAL NOT NULL,
  ended REAL,
  result TEXT NOT NULL,
  error_line INTEGER NOT NULL DEFAULT 0,
  error TEXT NOT NULL DEFAULT '',
  cycle_s REAL,
  estimate_s REAL,
  parts INTEGER NOT NULL DEFAULT 0,
  started_by TEXT NOT NULL DEFAULT '',
  from_line INTEGER NOT NULL DEFAULT 0);
CREATE INDEX IF NOT EXISTS jobs_started ON jobs(started);
)sql";

// A prepared statement, finalized when it goes.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr); }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return rc_ == SQLITE_OK; }
  sqlite3_stmt* get() { return s_; }
  void bind(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bind(int i, const std::optional<double>& v) {
    if (v) {
      sqlite3_bind_double(s_, i, *v);
    } else {
      sqlite3_bind_null(s_, i);
    }
  }
  void bind(int i, double v) { sqlite3_bind_double(s_, i, v); }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(s_, i, v); }
  void bind(int i, int v) { sqlite3_bind_int64(s_, i, v); }
  int step() { return sqlite3_step(s_); }
  std::string column_text(int i) {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(s_, i));
    return p != nullptr ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(s_, i)))
                        : std::string();
  }
  std::optional<double> column_real(int i) {
    if (sqlite3_column_type(s_, i) == SQLITE_NULL) return std::nullopt;
    return sqlite3_column_double(s_, i);
  }
  std::int64_t column_int(int i) { return sqlite3_column_int64(s_, i); }
  void column(int i, std::string& out) { out = column_text(i); }
  void column(int i, std::optional<double>& out) { out = column_real(i); }
  void column(int i, double& out) { out = column_real(i).value_or(0); }
  void column(int i, std::int64_t& out) { out = column_int(i); }
  void column(int i, int& out) { out = static_cast<int>(column_int(i)); }

 private:
  sqlite3_stmt* s_ = nullptr;
  int rc_ = SQLITE_ERROR;
};

// Every field but the id, as ?1 .. ?12.
void bind_record(Statement& s, const JobRecord& job) {
  int column = 0;
  for_each_job_field(job, [&](std::string_view name, const auto& value) {
    if (name != "id") s.bind(++column, value);
  });
}

}  // namespace

std::unique_ptr<JobStore> JobStore::open(const std::filesystem::path& path, bool mark_interrupted,
                                         std::string& error) {
  // A FIFO or a device there would hang or feed SQLite; a link could lead anywhere.
  std::error_code ec;
  const auto type = std::filesystem::symlink_status(path, ec).type();
  if (type != std::filesystem::file_type::not_found &&
      type != std::filesystem::file_type::regular) {
    error = "cannot open the job history " + path.string() + ": not a regular file";
    return nullptr;
  }
  sqlite3* db = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOFOLLOW, nullptr);
  std::unique_ptr<JobStore> store(new JobStore(db, path));
  if (rc != SQLITE_OK) {
    error = store->failure("cannot open");
    return nullptr;
  }
  sqlite3_busy_timeout(db, 2000);
  // WAL: a write is whole or absent after a crash. NORMAL syncs at checkpoints only: a power
  // loss may lose the last runs' rows, never the file.
  for (const char* sql : {"PRAGMA journal_mode=WAL", "PRAGMA synchronous=NORMAL", kSchema}) {
    if (error = store->exec(sql); !error.empty()) return nullptr;
  }
  if (!mark_interrupted) return store;
  Statement mark(db,
                 "UPDATE jobs SET result='interrupted', "
                 "error='the daemon stopped during the run' WHERE result='running'");
  if (!mark.ok() || mark.step() != SQLITE_DONE) {
    error = store->failure("cannot mark the runs cut short in");
    return nullptr;
  }
  store->interrupted_ = sqlite3_changes(db);
  return store;
}

JobStore::~JobStore() {
  sqlite3_close(db_);
}

namespace {

// SQLite's words, and the system's where a system call failed ("disk I/O error (No space left
// on device)").
std::string reason(sqlite3* db, const char* message) {
  std::string text = message;
  if (const int code = db != nullptr ? sqlite3_system_errno(db) : 0; code != 0)
    text += std::string(" (") + std::strerror(code) + ")";
  return text;
}

}  // namespace

std::string JobStore::failure(const char* what) const {
  return std::string(what) + " the job history " + path_.string() + ": " +
         (db_ != nullptr ? reason(db_, sqlite3_errmsg(db_)) : "out of memory");
}

std::string JobStore::exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) == SQLITE_OK) return "";
  std::string text = "cannot set up the job history " + path_.string() + ": " +
                     reason(db_, message != nullptr ? message : "unknown error");
  sqlite3_free(message);
  return text;
}

std::string JobStore::insert(JobRecord& job) {
  Statement s(db_,
              "INSERT INTO jobs(program, sha256, started, ended, result, error_line, error, "
              "cycle_s, estimate_s, parts, started_by, from_line) "
              "VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)");
  if (!s.ok()) return failure("cannot write to");
  bind_record(s, job);
  if (s.step() != SQLITE_DONE) return failure("cannot write to");
  job.id = sqlite3_last_insert_rowid(db_);
  return "";
}

std::string JobStore::finish(const JobRecord& job) {
  Statement s(db_,
              "UPDATE jobs SET program=?1, sha256=?2, started=?3, ended=?4, result=?5, "
              "error_line=?6, error=?7, cycle_s=?8, estimate_s=?9, parts=?10, started_by=?11, "
              "from_line=?12 WHERE id=?13");
  if (!s.ok()) return failure("cannot write to");
  bind_record(s, job);
  s.bind(13, job.id);
  if (s.step() != SQLITE_DONE) return failure("cannot write to");
  return "";
}

std::string JobStore::history(double since, int limit, std::vector<JobRecord>& out) {
  Statement s(db_,
              "SELECT id, program, sha256, started, ended, result, error_line, error, cycle_s, "
              "estimate_s, parts, started_by, from_line FROM jobs WHERE started >= ?1 "
              "ORDER BY id DESC LIMIT ?2");
  if (!s.ok()) return failure("cannot read");
  s.bind(1, since);
  s.bind(2, limit);
  int rc = 0;
  while ((rc = s.step()) == SQLITE_ROW) {
    JobRecord job;
    int column = 0;
    for_each_job_field(job, [&](std::string_view, auto& value) { s.column(column++, value); });
    out.push_back(std::move(job));
  }
  return rc == SQLITE_DONE ? "" : failure("cannot read");
}

std::string JobStore::stats(double since, JobStats& out) {
  Statement s(db_,
              "SELECT result, COUNT(*), SUM(parts), TOTAL(cycle_s), MAX(id) FROM jobs "
              "WHERE started >= ?1 GROUP BY result");
  if (!s.ok()) return failure("cannot read");
  s.bind(1, since);
  int rc = 0;
  while ((rc = s.step()) == SQLITE_ROW) {
    const std::string result = s.column_text(0);
    const std::int64_t jobs = s.column_int(1);
    const double cycle = s.column_real(3).value_or(0);
    out.by_result[result] = jobs;
    out.jobs += jobs;
    out.parts += s.column_int(2);
    out.cycle_s += cycle;
    if (result == "done") out.done_cycle_s = cycle;
    out.last_id = std::max(out.last_id, s.column_int(4));
  }
  return rc == SQLITE_DONE ? "" : failure("cannot read");
}

}  // namespace cncd::daemon
