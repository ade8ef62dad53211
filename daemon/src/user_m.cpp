#include "user_m.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>
#include <vector>

extern char** environ;

namespace cncd::daemon {

UserMProcess::~UserMProcess() {
  stop();
}

std::string UserMProcess::start(const std::string& executable, double p, double q,
                                double timeout_s) {
  stop();
  executable_ = executable;
  std::string p_text = fmt::format("{:f}", p);
  std::string q_text = fmt::format("{:f}", q);
  std::vector<char*> argv{executable_.data(), p_text.data(), q_text.data(), nullptr};
  // Its own process group: a timeout kills what it started too.
  posix_spawnattr_t attr;
  ::posix_spawnattr_init(&attr);
  ::posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  ::posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid = -1;
  const int error = ::posix_spawn(&pid, executable_.c_str(), nullptr, &attr, argv.data(), environ);
  ::posix_spawnattr_destroy(&attr);
  if (error != 0) return std::string("cannot run it: ") + std::strerror(error);
  pid_ = pid;
  timeout_s_ = timeout_s;
  deadline_ = std::chrono::steady_clock::now() +
              std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                  std::chrono::duration<double>(timeout_s));
  return "";
}

std::optional<std::string> UserMProcess::poll() {
  if (pid_ <= 0) return std::string();
  int status = 0;
  const pid_t done = ::waitpid(pid_, &status, WNOHANG);
  if (done == 0) {
    if (std::chrono::steady_clock::now() < deadline_) return std::nullopt;
    stop();
    return fmt::format("did not finish within {:g} s ([CNCD] USER_M_TIMEOUT) and was killed",
                       timeout_s_);
  }
  pid_ = -1;
  if (done < 0) return std::string("lost track of it: ") + std::strerror(errno);
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    return code == 0 ? std::string() : fmt::format("exited with status {}", code);
  }
  if (WIFSIGNALED(status)) return fmt::format("was killed by signal {}", WTERMSIG(status));
  return std::string("ended abnormally");
}

void UserMProcess::stop() {
  if (pid_ <= 0) return;
  ::kill(-pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
}

}  // namespace cncd::daemon
