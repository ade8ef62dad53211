// A thread that does its owner's jobs in the background (program.open's check, previews,
// cncd-web's estimates): it sleeps until the owner has a job or the thread is stopped. The
// owner keeps its jobs under mutex(); has_work and work run with the lock held, and work lets
// go of it while it works.
#pragma once

#include <sys/resource.h>
#include <unistd.h>

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace cncd::daemon {

class WorkerThread {
 public:
  using Lock = std::unique_lock<std::mutex>;

  WorkerThread() = default;
  ~WorkerThread() { stop(); }
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  // Starts the thread, once, at `nice` (0: the process's own priority; more: the servo
  // thread and the control socket come first).
  void start(int nice, std::function<bool()> has_work, std::function<void(Lock&)> work) {
    has_work_ = std::move(has_work);
    work_ = std::move(work);
    thread_ = std::thread([this, nice] { run(nice); });
  }
  std::mutex& mutex() { return mutex_; }
  // After a change under mutex() that may give the thread work.
  void wake() { wake_.notify_one(); }
  // Runs `last` under the lock (to cancel what is under way), then stops the thread and
  // waits for it. Owners call it first in their destructor, before their jobs go.
  void stop(const std::function<void()>& last = {}) {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      if (last) last();
    }
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void run(int nice) {
    if (nice != 0) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice);
    Lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stopping_ || has_work_(); });
      if (stopping_) return;
      work_(lock);
    }
  }

  std::function<bool()> has_work_;
  std::function<void(Lock&)> work_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace cncd::daemon
