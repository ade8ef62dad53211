// cncd as systemd runs it: readiness, status and watchdog notifications on $NOTIFY_SOCKET, a
// listening socket handed over by socket activation, and SIGTERM in the middle of a move.
#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

int unix_socket(const std::filesystem::path& path, int type) {
  const int fd = socket(AF_UNIX, type | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  if (fd < 0 || bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return -1;
  if (type == SOCK_STREAM && listen(fd, 16) != 0) return -1;
  return fd;
}

class NotifyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    notify_fd_ = unix_socket(dir_.path() / "notify", SOCK_DGRAM);
    ASSERT_GE(notify_fd_, 0);
    const auto ini = copy_example_machine(dir_.path());
    // The daemon inherits these, as from systemd; this process does not keep them.
    setenv("NOTIFY_SOCKET", (dir_.path() / "notify").c_str(), 1);
    setenv("WATCHDOG_USEC", "200000", 1);
    unsetenv("WATCHDOG_PID");
    const std::string error = daemon_.start(dir_.path(), {"--ini", ini.string()});
    unsetenv("NOTIFY_SOCKET");
    unsetenv("WATCHDOG_USEC");
    ASSERT_EQ(error, "");
  }
  void TearDown() override {
    if (notify_fd_ >= 0) close(notify_fd_);
  }

  // Collects notifications until `wanted` has come (true) or `limit` has passed (false).
  bool wait_for(const std::string& wanted, std::chrono::milliseconds limit) {
    const auto deadline = Clock::now() + limit;
    char buffer[4096];
    while (Clock::now() < deadline) {
      const ssize_t n = recv(notify_fd_, buffer, sizeof buffer, MSG_DONTWAIT);
      if (n <= 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        continue;
      }
      const std::string message(buffer, static_cast<std::size_t>(n));
      received_.push_back(message);
      if (message.find(wanted) != std::string::npos) return true;
    }
    return false;
  }

  TempDir dir_;
  DaemonProcess daemon_;
  int notify_fd_ = -1;
  std::vector<std::string> received_;
};

TEST_F(NotifyTest, ReadyStatusWatchdogAndStopping) {
  const auto all = [this] { return ::testing::PrintToString(received_); };
  EXPECT_TRUE(wait_for("READY=1", std::chrono::seconds(5))) << all();
  EXPECT_TRUE(wait_for("STATUS=estop", std::chrono::seconds(5))) << all();
  // Fed every half period while the servo loop runs.
  EXPECT_TRUE(wait_for("WATCHDOG=1", std::chrono::seconds(2))) << all();
  EXPECT_TRUE(wait_for("WATCHDOG=1", std::chrono::seconds(2))) << all();
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon_.socket()), "");
  ASSERT_TRUE(client.call("machine.reset").contains("result"));
  EXPECT_TRUE(wait_for("STATUS=off", std::chrono::seconds(5))) << all();
  daemon_.signal(SIGTERM);
  EXPECT_TRUE(wait_for("STOPPING=1", std::chrono::seconds(10))) << all();
  EXPECT_EQ(daemon_.stop(), 0);
}

TEST(SocketActivation, ServesTheHandedOverSocketAndLeavesItToSystemd) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path());
  const auto handed = dir.path() / "activated.sock";
  const auto own = dir.path() / "own.sock";
  const int listen_fd = unix_socket(handed, SOCK_STREAM);
  ASSERT_GE(listen_fd, 0);
  const pid_t pid = fork();
  if (pid == 0) {
    // As systemd does: the socket as fd 3, LISTEN_FDS and LISTEN_PID naming this process,
    // and the unit's StateDirectory= as $STATE_DIRECTORY.
    // When the socket already is fd 3, dup2 keeps its close-on-exec flag: clear it.
    if (dup2(listen_fd, 3) != 3 || fcntl(3, F_SETFD, 0) != 0) _exit(127);
    setenv("STATE_DIRECTORY", (dir.path() / "state").c_str(), 1);
    setenv("LISTEN_FDS", "1", 1);
    setenv("LISTEN_PID", std::to_string(getpid()).c_str(), 1);
    const int log = open((dir.path() / "cncd.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(log, STDERR_FILENO);
    dup2(log, STDOUT_FILENO);
    execl(CNCD_BINARY, CNCD_BINARY, "--ini", ini.c_str(), "--socket", own.c_str(), nullptr);
    _exit(127);
  }
  close(listen_fd);
  daemon::Client client;
  ASSERT_EQ(client.connect(handed.string()), "");
  const json answer = client.call("status.get", {{"fields", {"state"}}}, 20000);
  EXPECT_EQ(answer["result"]["state"], "estop") << answer.dump();
  EXPECT_FALSE(std::filesystem::exists(own));
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_TRUE(std::filesystem::exists(handed));  // systemd's to remove, not cncd's
  // The state files went to $STATE_DIRECTORY, the parameters starting from the seed.
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "state" / "sim_mm.position"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "state" / "sim_mm.var"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "sim_mm.position"));
}

TEST_F(MachineTest, SigtermDuringAMoveStopsOnThePathAndKeepsThePosition) {
  ready_machine();
  const auto program = dir_.write("long.ngc", "G21 G90 G1 F3000 X250\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const json moving = wait_until([](const json& s) { return s["velocity"].get<double>() > 40.0; });
  const double x_before = moving["position"]["commanded"]["x"].get<double>();
  EXPECT_EQ(daemon_.stop(), 0);
  EXPECT_NE(daemon_.log().find("aborted: daemon shutting down"), std::string::npos)
      << daemon_.log();
  // It came to rest past where it was seen moving, short of the end, and starts there again.
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  daemon::Client again;
  ASSERT_EQ(again.connect(daemon_.socket()), "");
  const json s = result_of(again.call("status.get"));
  const double x = s["position"]["actual"]["x"].get<double>();
  EXPECT_GT(x, x_before);
  EXPECT_LT(x, 250.0);
  EXPECT_NEAR(s["position"]["actual"]["y"].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(s["fault"], "");
  EXPECT_EQ(daemon_.stop(), 0);
}

}  // namespace
}  // namespace cncd::test
