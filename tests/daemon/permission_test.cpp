// Connections are authorized from the peer's credentials. The peers here are child processes
// that drop to an unprivileged user (and chosen groups) before they connect.
#include <grp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "client.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr uid_t kNobody = 65534;

// The sim machine with READ_GROUP and CONTROL_GROUP set to two groups every Debian system has.
std::string ini_with_groups() {
  std::ifstream in(std::string(CNCD_SOURCE_DIR) + "/config/examples/sim_mm.ini");
  std::stringstream text;
  text << in.rdbuf();
  std::string ini = relocate_example_ini(text.str());
  const std::string lines = "READ_GROUP = users\nCONTROL_GROUP = dialout\n";
  const auto section = ini.find("[CNCD]\n");
  if (section == std::string::npos) {
    ini += "\n[CNCD]\n" + lines;
  } else {
    ini.insert(section + 7, lines);
  }
  return ini;
}

gid_t group_id(const char* name) {
  const group* g = getgrnam(name);
  return g != nullptr ? g->gr_gid : 0;
}

// Runs `body` in a child process as uid/gid nobody with `groups`; returns its first output line.
std::string as_user(const std::vector<gid_t>& groups, const std::function<std::string()>& body) {
  int fds[2];
  if (pipe(fds) != 0) return "pipe failed";
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    std::string out;
    if (setgroups(groups.size(), groups.data()) != 0 || setresgid(kNobody, kNobody, kNobody) != 0 ||
        setresuid(kNobody, kNobody, kNobody) != 0) {
      out = "cannot drop privileges";
    } else {
      try {
        out = body();
      } catch (const std::exception& e) {
        out = std::string("exception: ") + e.what();
      }
    }
    out += "\n";
    [[maybe_unused]] const auto n = write(fds[1], out.data(), out.size());
    _exit(0);
  }
  close(fds[1]);
  std::string result;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0)
    result.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  waitpid(pid, nullptr, 0);
  return result.substr(0, result.find('\n'));
}

class PermissionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "needs root to act as other users";
    if (group_id("users") == 0 || group_id("dialout") == 0)
      GTEST_SKIP() << "no users/dialout group";
    // The socket's directory must be reachable by the unprivileged peers.
    chmod(dir_.path().c_str(), 0755);
    copy_example_machine(dir_.path());
    const auto ini = dir_.write("machine.ini", ini_with_groups());
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini.string()}), "");
  }

  std::string call_as(const std::vector<gid_t>& groups, const std::string& method) {
    return send_as(groups, {{"jsonrpc", "2.0"}, {"id", 1}, {"method", method}});
  }
  // Sends `request` (with id 1) as a peer in `groups`; its answer.
  std::string send_as(const std::vector<gid_t>& groups, const json& request) {
    const std::string socket = daemon_.socket();
    return as_user(groups, [&] {
      daemon::Client client;
      if (const auto error = client.connect(socket); !error.empty()) return error;
      try {
        client.send_raw(request.dump() + "\n");
      } catch (const std::exception&) {
        // A refused peer may find the connection closed before its request is out.
      }
      return client.read_line(5000);
    });
  }

  TempDir dir_;
  DaemonProcess daemon_;
};

TEST_F(PermissionTest, StrangerIsRefusedAtConnect) {
  const json reply = json::parse(call_as({}, "status.get"));
  EXPECT_EQ(reply["error"]["code"], 1005) << reply.dump();
  EXPECT_NE(reply["error"]["message"].get<std::string>().find("uid 65534"), std::string::npos);
}

TEST_F(PermissionTest, ReaderMayReadButNotCommand) {
  const json status = json::parse(call_as({group_id("users")}, "status.get"));
  EXPECT_EQ(status["result"]["state"], "estop") << status.dump();
  const json command = json::parse(call_as({group_id("users")}, "machine.reset"));
  EXPECT_EQ(command["error"]["code"], 1005) << command.dump();
}

TEST_F(PermissionTest, ReaderMayListToolsAndOffsetsButNotChangeThem) {
  const gid_t users = group_id("users");
  EXPECT_EQ(json::parse(call_as({users}, "tool.list"))["result"]["tools"].size(), 3u);
  EXPECT_EQ(json::parse(call_as({users}, "offsets.get"))["result"]["active"], "G54");
  for (const char* method : {"tool.set", "offsets.set", "program.step"}) {
    const json reply = json::parse(call_as({users}, method));
    EXPECT_EQ(reply["error"]["code"], 1005) << method << ": " << reply.dump();
  }
}

TEST_F(PermissionTest, ReaderMayNotSetOverrides) {
  for (const char* method : {"override.feed", "override.rapid", "override.spindle"}) {
    const json reply = json::parse(call_as({group_id("users")}, method));
    EXPECT_EQ(reply["error"]["code"], 1005) << method << ": " << reply.dump();
  }
  const json control = json::parse(call_as({group_id("dialout")}, "override.feed"));
  EXPECT_EQ(control["error"]["code"], -32602) << control.dump();  // allowed, but no value
}

TEST_F(PermissionTest, ControlGroupMayCommand) {
  const json command = json::parse(call_as({group_id("dialout")}, "machine.reset"));
  EXPECT_TRUE(command.contains("result")) << command.dump();
}

// A read-only peer cannot pass its requests off as someone else's, whatever it asks; a peer of
// the control group may, and the event log names the person through it.
TEST_F(PermissionTest, OnlyTheControlGroupMaySendOnBehalfOfSomeone) {
  const json alice = {{"user", "alice"}, {"address", "192.168.1.20"}, {"via", "web"}};
  for (const char* method : {"status.get", "machine.reset"}) {
    const json reply = json::parse(
        send_as({group_id("users")},
                {{"jsonrpc", "2.0"}, {"id", 1}, {"method", method}, {"on_behalf_of", alice}}));
    EXPECT_EQ(reply.value("/error/code"_json_pointer, 0), 1011) << method << ": " << reply.dump();
    EXPECT_NE(reply.dump().find("uid 65534"), std::string::npos) << reply.dump();
  }
  const json done = json::parse(send_as(
      {group_id("dialout")},
      {{"jsonrpc", "2.0"}, {"id", 1}, {"method", "machine.reset"}, {"on_behalf_of", alice}}));
  EXPECT_TRUE(done.contains("result")) << done.dump();
  daemon::Client reader;
  ASSERT_EQ(reader.connect(daemon_.socket()), "");
  const json events = reader.call("errors.list")["result"]["events"];
  ASSERT_FALSE(events.empty());
  const std::string by = events.back().value("by", "");
  EXPECT_EQ(by.rfind("alice@192.168.1.20 (web) via uid 65534 pid ", 0), 0u) << events.dump();
  EXPECT_EQ(events.back()["message"], "machine.reset by " + by);
}

}  // namespace
}  // namespace cncd::test
