// A user M code (M100-M199) run as LinuxCNC runs it: the executable with P and Q as its two
// arguments, without a shell, as the daemon's user, for at most a timeout. Not RT; one at a
// time, polled from the task's loop.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>

namespace cncd::daemon {

class UserMProcess {
 public:
  UserMProcess() = default;
  ~UserMProcess();
  UserMProcess(const UserMProcess&) = delete;
  UserMProcess& operator=(const UserMProcess&) = delete;

  // Starts `executable` with P and Q (written as LinuxCNC writes them, "%f"). Returns "" or
  // why it could not start.
  std::string start(const std::string& executable, double p, double q, double timeout_s);
  // While it runs: nothing. Once it has ended: "" when it exited with status 0, else what
  // happened ("exited with status 3", "was killed by signal 9", "did not finish within 60 s").
  // A process past its timeout is killed first.
  std::optional<std::string> poll();
  // Kills a running process and reaps it (abort, shutdown).
  void stop();
  bool running() const { return pid_ > 0; }
  const std::string& executable() const { return executable_; }

 private:
  pid_t pid_ = -1;
  std::string executable_;
  std::chrono::steady_clock::time_point deadline_{};
  double timeout_s_ = 0;
};

}  // namespace cncd::daemon
