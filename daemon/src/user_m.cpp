#include "user_m.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <pwd.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

#include <spdlog/spdlog.h>

namespace cncd::daemon {
namespace {

// Whether this process has started a user M code: only then are its descendants the M codes'
// (an in-process test harness has children of its own).
bool g_started_any = false;

}  // namespace

std::vector<std::string> user_m_environment() {
  std::string home = "/";
  if (const passwd* pw = ::getpwuid(::getuid());
      pw != nullptr && pw->pw_dir != nullptr && pw->pw_dir[0] != '\0')
    home = pw->pw_dir;
  return {"PATH=/usr/local/bin:/usr/bin:/bin", "HOME=" + home};
}

UserMProcess::~UserMProcess() {
  stop();
  tick();
  // At shutdown the grace is waited out here: nothing of the M codes outlives cncd.
  while (kill_at_ && std::chrono::steady_clock::now() < *kill_at_ && !descendants().empty())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (kill_at_) kill_all();
}

std::string UserMProcess::start(const std::string& executable, double p, double q,
                                double timeout_s) {
  if (pid_ > 0) stop();
  if (kill_at_) kill_all();  // what the last one left must not share this one's run
  if (!g_started_any) {
    // Helpers that leave their parent (setsid and a double fork) come to cncd, not to init:
    // they can be found and reaped.
    if (::prctl(PR_SET_CHILD_SUBREAPER, 1UL, 0UL, 0UL, 0UL) != 0)
      spdlog::warn("user M codes: cannot become a child subreaper: {}", std::strerror(errno));
    g_started_any = true;
  }
  executable_ = executable;
  std::string p_text = fmt::format("{:f}", p);
  std::string q_text = fmt::format("{:f}", q);
  std::vector<char*> argv{executable_.data(), p_text.data(), q_text.data(), nullptr};
  std::vector<std::string> environment = user_m_environment();
  std::vector<char*> envp;
  for (auto& entry : environment)
    envp.push_back(entry.data());
  envp.push_back(nullptr);
  // Its own process group, no signal blocked or ignored as cncd has them (SIGTERM is blocked
  // for cncd's signalfd), standard input /dev/null and no descriptor of cncd's beyond 0-2
  // (the program file, the sockets, the drives).
  posix_spawnattr_t attr;
  ::posix_spawnattr_init(&attr);
  ::posix_spawnattr_setflags(
      &attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  ::posix_spawnattr_setpgroup(&attr, 0);
  sigset_t none;
  ::sigemptyset(&none);
  ::posix_spawnattr_setsigmask(&attr, &none);
  sigset_t defaults;
  ::sigemptyset(&defaults);
  for (const int signal : {SIGPIPE, SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGCHLD, SIGUSR1, SIGUSR2})
    ::sigaddset(&defaults, signal);
  ::posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawn_file_actions_t files;
  ::posix_spawn_file_actions_init(&files);
  ::posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  ::posix_spawn_file_actions_addclosefrom_np(&files, STDERR_FILENO + 1);
  pid_t pid = -1;
  const int error =
      ::posix_spawn(&pid, executable_.c_str(), &files, &attr, argv.data(), envp.data());
  ::posix_spawn_file_actions_destroy(&files);
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
  if (!g_started_any || !has_children()) return;
  if (pid_ > 0) ::kill(-pid_, SIGTERM);
  // Its status is of no use now: the reaping in tick() takes it with the helpers'.
  pid_ = -1;
  // The rest of the tree is looked for in /proc from the next tick(): an estop's answer does
  // not wait for that.
  term_pending_ = true;
  if (!kill_at_) kill_at_ = std::chrono::steady_clock::now() + kKillGrace;
}

void UserMProcess::tick() {
  if (!g_started_any) return;
  reap_children(pid_);
  if (term_pending_) {
    term_pending_ = false;
    for (const pid_t pid : descendants())
      ::kill(pid, SIGTERM);
  }
  if (kill_at_ && std::chrono::steady_clock::now() >= *kill_at_) kill_all();
}

void UserMProcess::kill_all() {
  kill_at_.reset();
  term_pending_ = false;
  // A helper may fork while it is being killed: look again until nothing is left.
  for (int round = 0; round < 50; ++round) {
    const std::vector<pid_t> left = descendants();
    if (left.empty()) break;
    for (const pid_t pid : left)
      ::kill(pid, SIGKILL);
    reap_children(pid_);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  reap_children(pid_);
}

}  // namespace cncd::daemon
