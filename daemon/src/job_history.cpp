#include "job_history.hpp"

#include <fcntl.h>
#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <chrono>

#include <nlohmann/json.hpp>

#include "status_json.hpp"

namespace cncd::daemon {
namespace {

using nlohmann::json;

// A field as the job history's JSON shows it: a number not known (yet) is null.
template <class T>
json field_json(const T& value) {
  return value;
}
json field_json(const std::optional<double>& value) {
  return optional_number(value);
}

json job_json(const JobRecord& job) {
  json out = json::object();
  for_each_job_field(job,
                     [&](const char* name, const auto& value) { out[name] = field_json(value); });
  return out;
}

std::shared_ptr<const std::string> serialized(const json& value) {
  return std::make_shared<const std::string>(
      value.dump(-1, ' ', false, json::error_handler_t::replace));
}

}  // namespace

std::string file_sha256(const std::filesystem::path& path) {
  // Not a FIFO or device: open without blocking, then insist on a regular file.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return "";
  struct stat st {};
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  bool ok = fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && ctx &&
            EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) == 1;
  std::array<char, 65536> buffer{};
  while (ok) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n == 0) break;
    ok = n > 0 && EVP_DigestUpdate(ctx.get(), buffer.data(), static_cast<std::size_t>(n)) == 1;
  }
  ::close(fd);
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (!ok || EVP_DigestFinal_ex(ctx.get(), digest.data(), &length) != 1) return "";
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  for (unsigned int i = 0; i < length; ++i) {
    text += kHex[digest[i] >> 4];
    text += kHex[digest[i] & 15];
  }
  return text;
}

JobHistory::JobHistory(std::filesystem::path path)
    : path_(std::move(path)), thread_([this] { run(); }) {}

JobHistory::~JobHistory() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

std::uint64_t JobHistory::begin(JobRecord job) {
  std::uint64_t handle = 0;
  {
    std::lock_guard lock(mutex_);
    handle = next_handle_++;
    Row& row = rows_[handle];
    row.job = std::move(job);
    row.written = false;
  }
  wake_.notify_all();
  return handle;
}

void JobHistory::end(std::uint64_t handle, const JobRecord& job) {
  {
    std::lock_guard lock(mutex_);
    const auto found = rows_.find(handle);
    if (found == rows_.end()) return;  // given up on while the disk was full
    JobRecord& kept = found->second.job;
    kept.ended = job.ended;
    kept.result = job.result;
    kept.error_line = job.error_line;
    kept.error = job.error;
    kept.cycle_s = job.cycle_s;
    if (job.estimate_s) kept.estimate_s = job.estimate_s;
    kept.parts = job.parts;
    found->second.ended = true;
    found->second.written = false;
  }
  wake_.notify_all();
}

void JobHistory::ask_history(std::uint64_t token, double since, int limit) {
  {
    std::lock_guard lock(mutex_);
    asks_.push_back({token, false, since, limit});
  }
  wake_.notify_all();
}

void JobHistory::ask_stats(std::uint64_t token, double since) {
  {
    std::lock_guard lock(mutex_);
    asks_.push_back({token, true, since, 0});
  }
  wake_.notify_all();
}

std::vector<std::pair<std::uint64_t, TaskOutcome>> JobHistory::take() {
  std::lock_guard lock(mutex_);
  return std::exchange(answers_, {});
}

std::vector<std::pair<std::string, std::string>> JobHistory::take_reports() {
  std::lock_guard lock(mutex_);
  return std::exchange(reports_, {});
}

void JobHistory::report(const std::string& level, std::string message) {
  reports_.emplace_back(level, std::move(message));
}

void JobHistory::run() {
  // At once: the runs a crash cut short are marked, and reported, at the daemon's start.
  ensure_open();
  store_.reset();
  std::unique_lock lock(mutex_);
  for (;;) {
    auto pending = [this] {
      for (const auto& [handle, row] : rows_) {
        if (!row.written) return true;
      }
      return false;
    };
    // After a failed write, try again now and then: the disk may have room by then.
    const auto wait = store_problem_.empty() ? std::chrono::hours(24) : std::chrono::seconds(5);
    wake_.wait_for(lock, wait, [&] {
      return stopping_ || !asks_.empty() || (pending() && store_problem_.empty());
    });
    write_rows(lock);
    while (!asks_.empty()) {
      const Ask ask = asks_.front();
      asks_.pop_front();
      lock.unlock();
      TaskOutcome outcome = answer(ask);
      lock.lock();
      answers_.emplace_back(ask.token, std::move(outcome));
    }
    lock.unlock();
    store_.reset();
    lock.lock();
    if (stopping_) return;
  }
}

bool JobHistory::ensure_open() {
  if (store_) return true;
  std::string error;
  store_ = JobStore::open(path_, !marked_, error);
  if (!store_) {
    std::lock_guard lock(mutex_);
    if (store_problem_ != error)
      report("error", error + "; runs are kept in memory until it opens");
    store_problem_ = error;
    return false;
  }
  marked_ = true;
  if (const int cut = store_->interrupted(); cut > 0) {
    std::lock_guard lock(mutex_);
    report("warning", std::to_string(cut) + (cut == 1 ? " run" : " runs") +
                          " cut short by the daemon's end marked \"interrupted\" in " +
                          path_.string());
  }
  return true;
}

// Writes every row not yet written, the lock let go while SQLite works. Stops at the first
// failure: the rest wait for the next try.
void JobHistory::write_rows(std::unique_lock<std::mutex>& lock) {
  for (auto it = rows_.begin(); it != rows_.end();) {
    if (it->second.written) {
      ++it;
      continue;
    }
    const std::uint64_t handle = it->first;
    Row copy = it->second;
    lock.unlock();
    if (!copy.hashed) {
      copy.job.sha256 = file_sha256(copy.job.program);
      copy.hashed = true;
    }
    std::string error;
    if (!ensure_open()) {
      error = "not open";
    } else if (!copy.inserted) {
      error = store_->insert(copy.job);
      if (error.empty() && copy.ended) error = store_->finish(copy.job);
    } else {
      error = store_->finish(copy.job);
    }
    lock.lock();
    it = rows_.find(handle);
    if (it == rows_.end()) return;
    Row& row = it->second;
    row.hashed = true;
    row.job.sha256 = copy.job.sha256;
    // An insert gives the row its id even when the end's update after it failed.
    if (copy.job.id != 0) {
      row.job.id = copy.job.id;
      row.inserted = true;
    }
    if (!error.empty()) {
      if (error != "not open" && store_problem_ != error) {
        report("error", error + "; runs are kept in memory until it can be written");
      }
      if (error != "not open") store_problem_ = error;
      if (rows_.size() > kMaxUnwritten) {
        report("error", "job history: the oldest run kept in memory is dropped unwritten (" +
                            std::to_string(kMaxUnwritten) + " kept at the most)");
        rows_.erase(rows_.begin());
      }
      return;
    }
    if (!store_problem_.empty()) {
      report("info", "the job history " + path_.string() + " is written again");
      store_problem_.clear();
    }
    // Written as it was copied: unless end() came meanwhile, this row is done with.
    const bool changed = row.ended != copy.ended;
    row.written = !changed;
    if (row.written && row.ended) {
      it = rows_.erase(it);
    } else {
      ++it;
    }
  }
}

TaskOutcome JobHistory::answer(const Ask& ask) {
  if (!ensure_open()) {
    std::lock_guard lock(mutex_);
    return TaskError(TaskErrorKind::unavailable, store_problem_);
  }
  std::string error;
  json result;
  if (ask.stats) {
    JobStats stats;
    error = store_->stats(ask.since, stats);
    json by_result = json::object();
    for (const auto& [name, jobs] : stats.by_result)
      by_result[name] = jobs;
    result = json{{"jobs", stats.jobs},
                  {"by_result", by_result},
                  {"parts", stats.parts},
                  {"cycle_s", stats.cycle_s},
                  {"done_cycle_s", stats.done_cycle_s},
                  {"last_id", stats.last_id}};
  } else {
    std::vector<JobRecord> jobs;
    error = store_->history(ask.since, ask.limit, jobs);
    json list = json::array();
    for (const auto& job : jobs)
      list.push_back(job_json(job));
    result = json{{"jobs", std::move(list)}};
  }
  if (!error.empty()) return TaskError(TaskErrorKind::unavailable, error);
  return RawResult{serialized(result)};
}

}  // namespace cncd::daemon
