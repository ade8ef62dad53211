// Estimated run times of the programs in the list: `cncd-check --plan --json` run on a worker
// thread, one program at a time, cached by name, size and modification time. Unknown (null)
// until computed, and for programs cncd-check cannot plan.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>

#include "worker_thread.hpp"

namespace cncd::web {

class Estimates {
 public:
  // `check` is cncd-check, `ini` the machine's INI it plans for; an empty `check` computes
  // nothing.
  Estimates(std::filesystem::path check, std::filesystem::path ini);
  ~Estimates();
  Estimates(const Estimates&) = delete;
  Estimates& operator=(const Estimates&) = delete;

  // The estimate of that version of the program, or nullopt (then queued for computing when
  // it is not already known to fail).
  std::optional<double> get(const std::filesystem::path& file, std::int64_t size,
                            std::chrono::system_clock::time_point mtime);
  // An estimate learnt elsewhere (program.open's status): cached for that version.
  void put(const std::filesystem::path& file, std::int64_t size,
           std::chrono::system_clock::time_point mtime, double seconds);

 private:
  using Key = std::tuple<std::string, std::int64_t, std::int64_t>;
  void run(daemon::WorkerThread::Lock& lock);

  std::filesystem::path check_;
  std::filesystem::path ini_;
  std::map<Key, std::optional<double>> done_;  // nullopt: cncd-check could not tell
  std::deque<Key> queue_;
  daemon::WorkerThread worker_;  // guards done_ and queue_
};

}  // namespace cncd::web
