// A user M code (M100-M199) run as LinuxCNC runs it: the executable with P and Q as its two
// arguments, without a shell, as the daemon's user, for at most a timeout. Not RT; one at a
// time, polled from the task's loop.
//
// What it starts stays with it even in a session of its own: cncd is a child subreaper, so
// helpers whose parents end are handed to cncd rather than to init, and a timeout or the end of
// the run (done, abort, estop, shutdown: Task::finish_program) ends every process that descends
// from cncd (it starts no others), SIGTERM first and SIGKILL kKillGrace later. The executable gets
// none of cncd's descriptors (standard input is /dev/null, output and errors go where cncd's go)
// and only the environment user_m_environment() gives.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace cncd::daemon {

// The environment a user M code gets: PATH=/usr/local/bin:/usr/bin:/bin and HOME, the daemon
// user's home directory ("/" without one). Nothing of cncd's own.
std::vector<std::string> user_m_environment();

// The processes that descend from this one (children, theirs ...), zombies left out, read
// from /proc (user_m_tree.cpp).
std::vector<pid_t> descendants();
// Whether this process has a child, running or ended: without one it has no descendant (a
// subreaper gets the orphans of its tree).
bool has_children();
// Reaps the children that have ended (helpers handed to the subreaper) other than `keep`,
// whose status is someone else's to take.
void reap_children(pid_t keep);

class UserMProcess {
 public:
  static constexpr std::chrono::milliseconds kKillGrace{300};

  UserMProcess() = default;
  ~UserMProcess();
  UserMProcess(const UserMProcess&) = delete;
  UserMProcess& operator=(const UserMProcess&) = delete;

  // Starts `executable` with P and Q (written as LinuxCNC writes them, "%f"). Returns "" or
  // why it could not start.
  std::string start(const std::string& executable, double p, double q, double timeout_s);
  // While it runs: nothing. Once it has ended: "" when it exited with status 0, else what
  // happened ("exited with status 3", "was killed by signal 9", "did not finish within 60 s").
  // A process past its timeout is stopped first.
  std::optional<std::string> poll();
  // Ends a running M code and all that user M codes started: SIGTERM to its process group
  // now, to the rest of the tree at the next tick(), SIGKILL after kKillGrace. Does not wait
  // nor read /proc: an estop is not held up by it.
  void stop();
  // Called every loop: reaps the helpers handed to cncd and, once the grace after stop() has
  // passed, kills what is left.
  void tick();
  bool running() const { return pid_ > 0; }
  const std::string& executable() const { return executable_; }

 private:
  // SIGKILL to every descendant until none is left (a bounded number of rounds).
  void kill_all();

  pid_t pid_ = -1;
  std::string executable_;
  std::chrono::steady_clock::time_point deadline_{};
  double timeout_s_ = 0;
  std::optional<std::chrono::steady_clock::time_point> kill_at_;  // stop() was called
  bool term_pending_ = false;  // stop() was called: SIGTERM to the tree at the next tick()
};

}  // namespace cncd::daemon
