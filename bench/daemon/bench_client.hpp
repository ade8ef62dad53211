// A line-based JSON-RPC client of cncd for the daemon benchmarks, and the daemon they run.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <thread>
#include <vector>

namespace cncd::bench {

using Clock = std::chrono::steady_clock;

struct Conn {
  int fd = -1;
  std::string buffer;
};

inline int connect_to(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return -1;
  }
  // Reads never block: every wait is a poll with a time limit.
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  return fd;
}

inline bool send_line(const Conn& c, const std::string& line) {
  const std::string data = line + "\n";
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = send(c.fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EAGAIN) {
      pollfd p{c.fd, POLLOUT, 0};
      poll(&p, 1, 100);
      continue;
    }
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

// Reads whatever is there; returns complete lines.
inline std::vector<std::string> read_lines(Conn& c) {
  char chunk[65536];
  const ssize_t n = read(c.fd, chunk, sizeof chunk);
  if (n > 0) c.buffer.append(chunk, static_cast<std::size_t>(n));
  std::vector<std::string> lines;
  std::size_t nl;
  while ((nl = c.buffer.find('\n')) != std::string::npos) {
    lines.push_back(c.buffer.substr(0, nl));
    c.buffer.erase(0, nl + 1);
  }
  return lines;
}

// The next answer (a line with an "id") on `c`, skipping notifications; "" after `limit`.
inline std::string read_answer(Conn& c, std::chrono::seconds limit = std::chrono::seconds(10)) {
  const auto deadline = Clock::now() + limit;
  while (Clock::now() < deadline) {
    for (auto& line : read_lines(c)) {
      if (line.find("\"id\"") != std::string::npos) return line;
    }
    pollfd p{c.fd, POLLIN, 0};
    poll(&p, 1, 100);
  }
  return "";
}

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// A fresh directory for one run, with the sim_mm example files of `extensions` copied in.
inline std::filesystem::path bench_dir(std::initializer_list<const char*> extensions) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("cncd-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path examples = fs::path(CNCD_SOURCE_DIR) / "config/examples";
  for (const char* ext : extensions) {
    fs::copy_file(examples / (std::string("sim_mm") + ext), dir / (std::string("sim_mm") + ext),
                  fs::copy_options::overwrite_existing);
  }
  return dir;
}

// A program of `lines` lines of feed moves over a 200 x 150 mm field.
inline void write_program(const std::filesystem::path& path, long lines) {
  std::ofstream out(path);
  out << "G21 G90 G94\n";
  char line[64];
  for (long i = 1; i < lines - 1; ++i) {
    std::snprintf(line, sizeof line, "G1 X%.3f Y%.3f F3000\n", static_cast<double>(i % 200),
                  static_cast<double>((i / 200) % 150));
    out << line;
  }
  out << "M2\n";
}

// Starts args[0] with the rest as its arguments, its output to `log` when given; its pid.
inline pid_t spawn_process(std::vector<std::string> args, const std::string& log = "") {
  std::vector<char*> argv;
  for (auto& arg : args)
    argv.push_back(arg.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (!log.empty()) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
      }
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Starts cncd on `dir`/sim_mm.ini with `args` added to its command line; returns its pid.
// $CNCD_BENCH_BINARY names another cncd to run (an older build, to compare).
inline pid_t start_cncd(const std::filesystem::path& dir, const std::string& sock,
                        std::vector<std::string> args) {
  const std::string ini = (dir / "sim_mm.ini").string();
  const char* other = std::getenv("CNCD_BENCH_BINARY");
  const std::string binary = other != nullptr && *other != '\0' ? other : CNCD_BINARY;
  args.insert(args.begin(), {binary, "--ini", ini, "--socket", sock});
  return spawn_process(std::move(args));
}

// A connection to the daemon at `sock`, waiting up to 10 s for it to listen; exits without.
inline Conn connect_when_up(const std::string& sock) {
  Conn c;
  for (int i = 0; i < 500 && c.fd < 0; ++i) {
    c.fd = connect_to(sock);
    if (c.fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (c.fd < 0) {
    std::fprintf(stderr, "cncd did not start\n");
    std::exit(1);
  }
  return c;
}

}  // namespace cncd::bench
