// No client can lock the others out: a read-only user holding every connection it can get
// leaves a control client able to connect and estop, without the daemon flooding its log;
// and half-sent request lines on many connections do not grow the daemon without bound.
#include <grp.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "daemon_peer.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr uid_t kNobody = 65534;

// The sim machine with the "users" group as READ_GROUP.
std::filesystem::path reader_machine(const TempDir& dir) {
  copy_example_machine(dir.path());
  std::string ini = slurp(dir.path() / "sim_mm.ini");
  ini.insert(ini.find("[CNCD]\n") + 7, "READ_GROUP = users\n");
  return dir.write("machine.ini", ini);
}

// A child process as uid nobody in the read group, holding as many of `tries` connections as
// the daemon keeps until told to let go.
class Holder {
 public:
  Holder(const std::string& socket, gid_t group, int tries) {
    int up[2];
    int down[2];
    if (pipe(up) != 0 || pipe(down) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      close(up[0]);
      close(down[1]);
      std::string report = "cannot drop privileges";
      if (setgroups(1, &group) == 0 && setresgid(kNobody, kNobody, kNobody) == 0 &&
          setresuid(kNobody, kNobody, kNobody) == 0) {
        report = hold(socket, tries);
      }
      report += "\n";
      [[maybe_unused]] auto n = write(up[1], report.data(), report.size());
      char c;
      [[maybe_unused]] auto m = read(down[0], &c, 1);  // until released: then all close
      _exit(0);
    }
    close(up[1]);
    close(down[0]);
    release_fd_ = down[1];
    char buffer[256];
    const ssize_t n = read(up[0], buffer, sizeof buffer);
    if (n > 0) report_.assign(buffer, static_cast<std::size_t>(n));
    close(up[0]);
  }
  ~Holder() {
    if (release_fd_ >= 0) close(release_fd_);
    if (pid_ > 0) waitpid(pid_, nullptr, 0);
  }
  Holder(const Holder&) = delete;
  Holder& operator=(const Holder&) = delete;
  // "held H refused R": connections still open, and those refused with error 1010.
  const std::string& report() const { return report_; }

 private:
  static std::string hold(const std::string& socket, int tries) {
    std::vector<int> fds;
    for (int i = 0; i < tries; ++i) {
      int fd = -1;
      for (int attempt = 0; attempt < 200 && fd < 0; ++attempt) {
        fd = raw_connect(socket);
        if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      if (fd >= 0) fds.push_back(fd);
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    int held = 0;
    int refused = 0;
    for (const int fd : fds) {
      const std::string text = received(fd);
      if (text.find("\"code\":1010") != std::string::npos) {
        ++refused;
      } else if (text.empty()) {
        ++held;
      }
    }
    return "held " + std::to_string(held) + " refused " + std::to_string(refused);
  }

  pid_t pid_ = -1;
  int release_fd_ = -1;
  std::string report_;
};

TEST(ConnectionLimits, AReaderHoldingEveryConnectionLeavesRoomForAnEstop) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to act as another user";
  const group* users = getgrnam("users");
  if (users == nullptr) GTEST_SKIP() << "no users group";
  TempDir dir;
  chmod(dir.path().c_str(), 0755);
  const auto ini = reader_machine(dir);
  // The daemon gets 200 descriptors, fewer than the reader tries to take.
  rlimit saved{};
  getrlimit(RLIMIT_NOFILE, &saved);
  rlimit low = saved;
  low.rlim_cur = 200;
  setrlimit(RLIMIT_NOFILE, &low);
  DaemonProcess daemon;
  const std::string started = daemon.start(dir.path(), {"--ini", ini.string()});
  setrlimit(RLIMIT_NOFILE, &saved);
  ASSERT_EQ(started, "");
  daemon::Client control;
  ASSERT_EQ(control.connect(daemon.socket()), "");
  ASSERT_TRUE(control.call("machine.reset").contains("result"));

  Holder holder(daemon.socket(), users->gr_gid, 300);
  int held = 0;
  int refused = 0;
  ASSERT_EQ(std::sscanf(holder.report().c_str(), "held %d refused %d", &held, &refused), 2)
      << holder.report();
  EXPECT_GT(held, 0) << holder.report();
  EXPECT_GT(refused, 0) << "connections past the limit are refused with error 1010; "
                        << holder.report();
  const std::size_t lines_before = line_count(daemon.log());
  const auto estop =
      run_command({"/usr/bin/timeout", "20", CNCCTL_BINARY, "--socket", daemon.socket(), "estop"});
  EXPECT_EQ(estop.exit_status, 0) << estop.out << estop.err;
  EXPECT_EQ(control.call("status.get")["result"]["state"], "estop");
  // Held for a few seconds more, the connections add (next to) nothing to the log.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const std::string log = daemon.log();
  EXPECT_LT(line_count(log), lines_before + 10)
      << log.substr(log.size() - std::min<std::size_t>(log.size(), 2000));
}

// AddressSanitizer keeps freed blocks in a quarantine of up to 256 MiB, which the resident size
// would count as the daemon's: the daemon started here runs without it (it inherits this).
class NoQuarantine {
 public:
  NoQuarantine() {
    const char* options = std::getenv("ASAN_OPTIONS");
    had_ = options != nullptr;
    if (had_) saved_ = options;
    setenv("ASAN_OPTIONS", (saved_ + ":quarantine_size_mb=0").c_str(), 1);
  }
  ~NoQuarantine() {
    if (had_) {
      setenv("ASAN_OPTIONS", saved_.c_str(), 1);
    } else {
      unsetenv("ASAN_OPTIONS");
    }
  }
  NoQuarantine(const NoQuarantine&) = delete;
  NoQuarantine& operator=(const NoQuarantine&) = delete;

 private:
  bool had_ = false;
  std::string saved_;
};

TEST(ConnectionLimits, HalfSentLinesOnManyConnectionsStayWithinABudget) {
  TempDir dir;
  DaemonProcess daemon;
  {
    const NoQuarantine no_quarantine;
    ASSERT_EQ(daemon.start(dir.path(), {"--ini", copy_example_machine(dir.path()).string()}), "");
  }
  const pid_t pid = serving_pid(daemon.socket());
  ASSERT_GT(pid, 0);
  daemon::Client control;
  ASSERT_EQ(control.connect(daemon.socket()), "");
  ASSERT_TRUE(control.call("status.get").contains("result"));
  const long rss_before = resident_kib(pid);
  // 200 connections each send a request line 1 KiB short of the 1 MiB limit, and no newline.
  const std::string part = R"({"jsonrpc":"2.0","id":1,"method":"status.get","params":{"x":")" +
                           std::string((1 << 20) - 1024, 'a');
  std::vector<int> fds;
  for (int i = 0; i < 200; ++i) {
    const int fd = raw_connect(daemon.socket());
    ASSERT_GE(fd, 0) << "connection " << i;
    fds.push_back(fd);
    send_for(fd, part, std::chrono::milliseconds(2000));
  }
  // What was sent has been read (or refused) once the daemon answers a request after it.
  ASSERT_TRUE(control.call("status.get").contains("result"));
  const long grown_mib = (resident_kib(pid) - rss_before) / 1024;
  EXPECT_LT(grown_mib, 100) << "the daemon grew by " << grown_mib << " MiB";
  int told = 0;
  for (const int fd : fds) {
    told += received(fd).find("\"code\":1006") != std::string::npos ? 1 : 0;
    close(fd);
  }
  EXPECT_GT(told, 0) << "connections past the input budget are told why they are closed";
  EXPECT_EQ(control.call("status.get")["result"]["state"], "estop");
}

}  // namespace
}  // namespace cncd::test
