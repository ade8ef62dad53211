#include "estimates.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

namespace cncd::web {
namespace {

constexpr std::size_t kMaxCached = 4096;
constexpr std::size_t kMaxQueued = 256;

std::int64_t ticks(std::chrono::system_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

// stdout of argv, or nullopt when it could not run or failed.
std::optional<std::string> output_of(const std::vector<std::string>& argv) {
  std::vector<char*> args;  // built before fork: the child only calls async-signal-safe code
  for (const auto& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return std::nullopt;
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return std::nullopt;
  }
  if (pid == 0) {
    const int null_fd = open("/dev/null", O_RDWR);
    dup2(null_fd, STDIN_FILENO);
    dup2(fds[1], STDOUT_FILENO);
    dup2(null_fd, STDERR_FILENO);
    execv(args[0], args.data());
    _exit(127);
  }
  close(fds[1]);
  std::string out;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n > 0) {
      if (out.size() < (1u << 20)) out.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return out;
}

}  // namespace

Estimates::Estimates(std::filesystem::path check, std::filesystem::path ini)
    : check_(std::move(check)), ini_(std::move(ini)) {
  if (!check_.empty()) {
    worker_.start(
        0, [this] { return !queue_.empty(); },
        [this](daemon::WorkerThread::Lock& lock) { run(lock); });
  }
}

Estimates::~Estimates() {
  worker_.stop();
}

std::optional<double> Estimates::get(const std::filesystem::path& file, std::int64_t size,
                                     std::chrono::system_clock::time_point mtime) {
  const Key key{file.string(), size, ticks(mtime)};
  std::lock_guard lock(worker_.mutex());
  if (const auto found = done_.find(key); found != done_.end()) return found->second;
  if (!check_.empty() && queue_.size() < kMaxQueued &&
      std::find(queue_.begin(), queue_.end(), key) == queue_.end()) {
    queue_.push_back(key);
    worker_.wake();
  }
  return std::nullopt;
}

void Estimates::put(const std::filesystem::path& file, std::int64_t size,
                    std::chrono::system_clock::time_point mtime, double seconds) {
  std::lock_guard lock(worker_.mutex());
  if (done_.size() >= kMaxCached) done_.clear();
  done_[Key{file.string(), size, ticks(mtime)}] = seconds;
}

void Estimates::run(daemon::WorkerThread::Lock& lock) {
  const Key key = queue_.front();
  lock.unlock();
  std::optional<double> seconds;
  if (const auto out = output_of(
          {check_.string(), "--plan", "--json", "--ini", ini_.string(), std::get<0>(key)})) {
    const auto json = nlohmann::json::parse(*out, nullptr, false);
    if (json.is_object() && json.value("cycle_time_s", nlohmann::json()).is_number())
      seconds = json["cycle_time_s"].get<double>();
  }
  lock.lock();
  queue_.pop_front();
  if (done_.size() >= kMaxCached) done_.clear();
  done_[key] = seconds;
}

}  // namespace cncd::web
