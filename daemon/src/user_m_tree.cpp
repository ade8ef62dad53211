// The processes user M codes started, found by their descent from cncd in /proc.
#include <dirent.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>

#include "user_m.hpp"

namespace cncd::daemon {
namespace {

struct ProcEntry {
  pid_t parent = 0;
  bool zombie = false;
};

// /proc/<pid>/stat: "pid (comm) state ppid ..."; comm may hold spaces and parentheses, so the
// fields are read after its last ')'.
bool read_stat(pid_t pid, ProcEntry& out) {
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%d/stat", static_cast<int>(pid));
  std::FILE* file = std::fopen(path, "re");
  if (file == nullptr) return false;
  char text[512];
  const std::size_t n = std::fread(text, 1, sizeof text - 1, file);
  std::fclose(file);
  text[n] = '\0';
  const char* close = std::strrchr(text, ')');
  if (close == nullptr) return false;
  char state = 0;
  int parent = 0;
  if (std::sscanf(close + 1, " %c %d", &state, &parent) != 2) return false;
  out.parent = parent;
  out.zombie = state == 'Z' || state == 'X';
  return true;
}

}  // namespace

std::vector<pid_t> descendants() {
  std::map<pid_t, ProcEntry> table;
  if (DIR* dir = ::opendir("/proc")) {
    while (const dirent* entry = ::readdir(dir)) {
      char* end = nullptr;
      const long pid = std::strtol(entry->d_name, &end, 10);
      if (end == entry->d_name || *end != '\0' || pid <= 0) continue;
      ProcEntry proc;
      if (read_stat(static_cast<pid_t>(pid), proc)) table[static_cast<pid_t>(pid)] = proc;
    }
    ::closedir(dir);
  }
  const pid_t self = ::getpid();
  std::set<pid_t> tree{self};
  // Parents before children is not guaranteed by pid order (pids wrap): grow until stable.
  for (bool grew = true; grew;) {
    grew = false;
    for (const auto& [pid, proc] : table) {
      if (tree.count(pid) == 0 && tree.count(proc.parent) != 0) {
        tree.insert(pid);
        grew = true;
      }
    }
  }
  std::vector<pid_t> out;
  for (const pid_t pid : tree) {
    if (pid != self && !table[pid].zombie) out.push_back(pid);
  }
  return out;
}

bool has_children() {
  siginfo_t info{};
  return ::waitid(P_ALL, 0, &info, WEXITED | WNOHANG | WNOWAIT) == 0 || errno != ECHILD;
}

void reap_children(pid_t keep) {
  for (int i = 0; i < 256; ++i) {
    siginfo_t info{};
    if (::waitid(P_ALL, 0, &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid == 0) return;
    if (info.si_pid == keep) return;  // its status is poll()'s
    ::waitpid(info.si_pid, nullptr, WNOHANG);
  }
}

}  // namespace cncd::daemon
