// Looking at the daemon from outside: its pid (from a connection's peer credentials), whether
// it is stopped, its resident memory; and raw non-blocking connections that tests hold open.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace cncd::test {

// A connected, non-blocking socket to `path`; -1 when the connection is refused or would block.
inline int raw_connect(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// The pid of the process serving `path`, from the peer credentials of a connection to it.
inline pid_t serving_pid(const std::string& path) {
  const int fd = raw_connect(path);
  if (fd < 0) return -1;
  ucred cred{};
  socklen_t len = sizeof cred;
  const bool ok = getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) == 0;
  ::close(fd);
  return ok ? cred.pid : -1;
}

// The state letter of /proc/PID/stat ('T' once a SIGSTOP has taken effect).
inline char process_state(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto paren = text.rfind(')');
  return paren != std::string::npos && paren + 2 < text.size() ? text[paren + 2] : '?';
}

inline bool wait_for_state(pid_t pid, char state) {
  for (int i = 0; i < 1000; ++i) {
    if (process_state(pid) == state) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// VmRSS of `pid` in KiB; -1 when unknown.
inline long resident_kib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// Sends as much of `bytes` as the peer takes within `limit`; returns how much went out (short
// when the peer closed the connection or stopped reading).
inline std::size_t send_for(int fd, const std::string& bytes, std::chrono::milliseconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  std::size_t sent = 0;
  while (sent < bytes.size() && std::chrono::steady_clock::now() < deadline) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd p{fd, POLLOUT, 0};
      ::poll(&p, 1, 20);
    } else {
      break;
    }
  }
  return sent;
}

// Whatever the peer has sent so far, without waiting.
inline std::string received(int fd) {
  std::string out;
  char buffer[4096];
  ssize_t n;
  while ((n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT)) > 0)
    out.append(buffer, static_cast<std::size_t>(n));
  return out;
}

inline std::size_t line_count(const std::string& text) {
  std::size_t n = 0;
  for (const char c : text)
    n += c == '\n' ? 1 : 0;
  return n;
}

}  // namespace cncd::test
