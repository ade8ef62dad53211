// User M codes on the real daemon: what one starts dies with it after a timeout and an estop,
// even in a session of its own or behind a double fork, and it runs without cncd's descriptors
// and with only the documented environment.
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// The live processes whose command line or environment holds `marker`; with `named`, those
// whose own name (argv[0]) holds it: the helpers themselves, not a setsid on its way to them.
std::vector<pid_t> marked(const std::string& marker, bool named = false) {
  std::vector<pid_t> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.empty() || !std::all_of(name.begin(), name.end(), ::isdigit)) continue;
    const std::string stat = slurp(entry.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos || close + 2 >= stat.size() || stat[close + 2] == 'Z') continue;
    const std::string cmdline = slurp(entry.path() / "cmdline");
    if (named ? std::string(cmdline.c_str()).find(marker) != std::string::npos
              : cmdline.find(marker) != std::string::npos ||
                    slurp(entry.path() / "environ").find(marker) != std::string::npos)
      out.push_back(static_cast<pid_t>(std::stoi(name)));
  }
  return out;
}

class UserMDaemon : public MachineTest {
 protected:
  void SetUp() override {
    MachineTest::SetUp();
    marker_ = "cncd-user-m-test-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name();
  }
  void TearDown() override {
    for (const pid_t pid : marked(marker_))
      ::kill(pid, SIGKILL);  // what the daemon left behind, so that no failure leaks them
  }
  void restart_with(const std::string& cncd_keys) {
    daemon_.stop();
    std::string text = slurp(ini_);
    text.insert(text.find("[CNCD]\n") + 7, cncd_keys);
    text.insert(text.find("[RS274NGC]\n") + 11, "USER_M_PATH = um\n");
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  // M105: records its environment and descriptors, starts a helper in a session of its own and
  // one behind a double fork (both named by the marker), says so, then sleeps.
  void write_m105() {
    std::filesystem::create_directories(dir_.path() / "um");
    const std::string sleeper = (dir_.path() / marker_).string();
    std::filesystem::create_symlink("/bin/sleep", sleeper);
    const std::string out = dir_.path().string();
    const auto path = dir_.write("um/M105",
                                 "#!/bin/sh\n"
                                 "tr '\\0' '\\n' < /proc/$$/environ > " +
                                     out +
                                     "/env.txt\n"
                                     "ls -l /proc/$$/fd > " +
                                     out +
                                     "/fd.txt\n"
                                     "setsid " +
                                     sleeper +
                                     " 1000 > /dev/null 2>&1 &\n"
                                     "( " +
                                     sleeper +
                                     " 1001 > /dev/null 2>&1 & ) &\n"
                                     "sleep 0.2\n"
                                     "echo started > " +
                                     out +
                                     "/started\n"
                                     "exec sleep 1002\n");
    ::chmod(path.c_str(), 0755);
  }
  // Starts M105 in a program and waits until its helpers run: both are there.
  void start_m105() {
    write_m105();
    ready_machine();
    start_program("um.ngc", "G0 X1\nM105\nG0 X2\nM2\n");
    wait_until([&](const json& s) {
      return std::filesystem::exists(dir_.path() / "started") || s["exec"] == "idle";
    });
    ASSERT_TRUE(std::filesystem::exists(dir_.path() / "started"));
    // Both were started before the file was written; a loaded machine may take a while to
    // get them through setsid and the subshell.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (marked(marker_, true).size() < 2 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_EQ(marked(marker_, true).size(), 2U) << "the helpers did not start";
  }
  // Whether every marked process has gone within `limit`.
  bool all_gone(std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!marked(marker_).empty()) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  }
  std::string marker_;
};

TEST_F(UserMDaemon, ATimeoutEndsEverythingTheMCodeStarted) {
  ASSERT_NO_FATAL_FAILURE(restart_with("USER_M_TIMEOUT = 5\n"));
  ASSERT_NO_FATAL_FAILURE(start_m105());
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "error");
  EXPECT_NE(s["program"].value("error", "").find("M105 did not finish within 5 s"),
            std::string::npos)
      << s["program"].dump();
  EXPECT_TRUE(all_gone(std::chrono::seconds(10))) << marked(marker_).size() << " survive";
}

TEST_F(UserMDaemon, AnEstopEndsEverythingTheMCodeStarted) {
  ASSERT_NO_FATAL_FAILURE(restart_with(""));
  ASSERT_NO_FATAL_FAILURE(start_m105());
  result_of(call("machine.estop"));
  EXPECT_EQ(status()["exec"], "idle");
  EXPECT_TRUE(all_gone(std::chrono::seconds(10))) << marked(marker_).size() << " survive";
  // The daemon goes on: the next program runs.
  result_of(call("machine.reset"));
  EXPECT_EQ(status()["state"], "off");
}

TEST_F(UserMDaemon, TheMCodeGetsNoDescriptorOfCncdsAndOnlyTheDocumentedEnvironment) {
  ASSERT_NO_FATAL_FAILURE(restart_with(""));
  ASSERT_NO_FATAL_FAILURE(start_m105());
  result_of(call("program.abort"));
  EXPECT_TRUE(all_gone(std::chrono::seconds(10))) << marked(marker_).size() << " survive";
  std::istringstream env(slurp(dir_.path() / "env.txt"));
  std::set<std::string> names;
  std::string line;
  while (std::getline(env, line)) {
    names.insert(line.substr(0, line.find('=')));
    if (line.starts_with("PATH=")) {
      EXPECT_EQ(line, "PATH=/usr/local/bin:/usr/bin:/bin");
    }
  }
  EXPECT_EQ(names, (std::set<std::string>{"HOME", "PATH"})) << slurp(dir_.path() / "env.txt");
  const std::string fds = slurp(dir_.path() / "fd.txt");
  EXPECT_EQ(fds.find("um.ngc"), std::string::npos) << fds;
  EXPECT_EQ(fds.find("socket:"), std::string::npos) << fds;
  EXPECT_NE(fds.find(" 0 -> /dev/null"), std::string::npos) << fds;
}

}  // namespace
}  // namespace cncd::test
