// `cncd-web --ini INI user ...` and `key ...` on a real users file, from a pipe and a terminal.
#include "cncd/web/admin_cli.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "temp_dir.hpp"

namespace cncd::web {
namespace {

class AdminCliTest : public test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    web_.users_file = dir_ / "state/web-users";
    options_.cost = {1, 64, 1};
  }
  // Runs one command with `input` on standard input; returns its exit status.
  int run(const std::vector<std::string>& args, const std::string& input = "") {
    std::istringstream in(input);
    out_.str("");
    err_.str("");
    return run_admin_command(args, web_, in, out_, err_, options_);
  }
  UsersFile users() {
    UsersFile file(web_.users_file);
    EXPECT_EQ(file.load(), "");
    return file;
  }

  config::WebConfig web_;
  AdminOptions options_;
  std::ostringstream out_;
  std::ostringstream err_;
};

TEST_F(AdminCliTest, AddListPasswdDelete) {
  ASSERT_EQ(run({"user", "add", "alice", "--role", "operator"}, "pw one\n"), 0) << err_.str();
  EXPECT_EQ(err_.str(), "added user alice (operator) to " + web_.users_file.string() + "\n");
  ASSERT_EQ(run({"user", "add", "bob", "--role=admin"}, "pw two"), 0) << err_.str();
  EXPECT_NE(users().check_password("alice", "pw one"), nullptr);
  EXPECT_NE(users().check_password("bob", "pw two"), nullptr);  // no final newline needed

  ASSERT_EQ(run({"user", "list"}), 0);
  EXPECT_EQ(out_.str(),
            "alice                            operator password    keys:\n"
            "bob                              admin    password    keys:\n");

  ASSERT_EQ(run({"user", "passwd", "alice"}, "pw three\r\n"), 0) << err_.str();
  EXPECT_EQ(users().check_password("alice", "pw one"), nullptr);
  EXPECT_NE(users().check_password("alice", "pw three"), nullptr);

  ASSERT_EQ(run({"user", "del", "bob"}), 0) << err_.str();
  EXPECT_EQ(users().find("bob"), nullptr);
  EXPECT_EQ(users().users().size(), 1u);
}

TEST_F(AdminCliTest, AKeyIsPrintedOnceAndWorks) {
  ASSERT_EQ(run({"user", "add", "cam", "--role", "setter"}, "pw\n"), 0);
  ASSERT_EQ(run({"key", "add", "cam"}), 0) << err_.str();
  std::string key = out_.str();
  ASSERT_TRUE(key.ends_with("\n"));
  key.pop_back();
  EXPECT_TRUE(key.starts_with("cncd_")) << key;
  const auto file = users();
  ASSERT_EQ(file.check_key(key), file.find("cam"));
  const std::string id = file.find("cam")->keys.at(0).id;
  EXPECT_EQ(err_.str(), "key " + id + " added for cam; it is shown only this once:\n");

  ASSERT_EQ(run({"user", "list"}), 0);
  EXPECT_NE(out_.str().find("keys: " + id), std::string::npos) << out_.str();
  EXPECT_EQ(out_.str().find(key), std::string::npos);

  EXPECT_EQ(run({"key", "del", "cam", "ffffffff"}), 1);
  EXPECT_EQ(err_.str(),
            "cncd-web: " + web_.users_file.string() + ": user 'cam' has no key ffffffff\n");
  ASSERT_EQ(run({"key", "del", "cam", id}), 0) << err_.str();
  EXPECT_EQ(users().check_key(key), nullptr);
}

TEST_F(AdminCliTest, MistakesAreExplainedAndChangeNothing) {
  const std::string file = web_.users_file.string();
  EXPECT_EQ(run({"user", "add", "alice", "--role", "boss"}, "pw\n"), 2);
  EXPECT_TRUE(err_.str().starts_with(
      "cncd-web: 'boss' is not a role (observer|operator|setter|admin)\nusage:"))
      << err_.str();
  EXPECT_EQ(run({"user", "add", "alice"}, "pw\n"), 2);
  EXPECT_TRUE(err_.str().starts_with("cncd-web: user add needs NAME and --role ROLE\n"));
  EXPECT_EQ(run({"user", "add", "al ice", "--role", "admin"}, "pw\n"), 1);
  EXPECT_EQ(err_.str(), "cncd-web: " + file +
                            ": 'al ice': a user name has only letters, digits, '_', '.' and '-'\n");
  EXPECT_EQ(run({"user", "add", "alice", "--role", "admin"}, ""), 1);
  EXPECT_EQ(err_.str(), "cncd-web: no password on standard input (one line expected)\n");
  EXPECT_EQ(run({"user", "add", "alice", "--role", "admin"}, "\n"), 1);
  EXPECT_EQ(err_.str(), "cncd-web: " + file + ": the password is empty\n");
  EXPECT_FALSE(std::filesystem::exists(web_.users_file));

  ASSERT_EQ(run({"user", "add", "alice", "--role", "admin"}, "pw\n"), 0);
  EXPECT_EQ(run({"user", "add", "alice", "--role", "admin"}, "pw\n"), 1);
  EXPECT_EQ(err_.str(), "cncd-web: " + file + ": user 'alice' exists already\n");
  EXPECT_EQ(run({"user", "del", "nobody"}), 1);
  EXPECT_EQ(err_.str(), "cncd-web: " + file + ": no user 'nobody'\n");
  EXPECT_EQ(run({"user", "passwd", "nobody"}, "pw\n"), 1);
  EXPECT_EQ(run({"key", "add", "nobody"}), 1);
  EXPECT_EQ(run({"user", "frobnicate"}), 2);
  EXPECT_TRUE(err_.str().starts_with("cncd-web: unknown command 'user frobnicate'\n"));
  EXPECT_EQ(run({"user", "del"}), 2);
  EXPECT_EQ(run({"user", "list", "extra"}), 2);

  std::filesystem::permissions(web_.users_file, std::filesystem::perms::group_read,
                               std::filesystem::perm_options::add);
  EXPECT_EQ(run({"user", "list"}), 1);
  EXPECT_EQ(err_.str(), "cncd-web: " + file + ": mode 0640 lets the group or others at the " +
                            "password hashes; chmod 600 " + file + "\n");
  web_.users_file.clear();
  EXPECT_EQ(run({"user", "list"}), 1);
  EXPECT_EQ(err_.str(), "cncd-web: no users file: set [WEB] USERS_FILE or a state directory\n");
  EXPECT_TRUE(is_admin_command({"user", "list"}));
  EXPECT_TRUE(is_admin_command({"key"}));
  EXPECT_FALSE(is_admin_command({"--www", "x"}));
  EXPECT_FALSE(is_admin_command({}));
}

// On a terminal the password is asked twice, without echo, and the terminal is restored.
class TerminalTest : public AdminCliTest {
 protected:
  void SetUp() override {
    AdminCliTest::SetUp();
    ASSERT_EQ(::openpty(&master_, &slave_, nullptr, nullptr, nullptr), 0);
    options_.input_fd = slave_;
    ASSERT_EQ(::tcgetattr(slave_, &before_), 0);
  }
  void TearDown() override {
    ::close(master_);
    ::close(slave_);
    AdminCliTest::TearDown();
  }
  // Runs the command reading from the terminal, typing `typed` once echo is off (as a person
  // types after the prompt).
  int type_and_run(const std::vector<std::string>& args, const std::string& typed) {
    std::ifstream in("/proc/self/fd/" + std::to_string(slave_));
    out_.str("");
    err_.str("");
    std::thread typist([&] {
      termios now{};
      for (int i = 0; i < 10000; ++i) {
        if (::tcgetattr(slave_, &now) == 0 && (now.c_lflag & ECHO) == 0) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      EXPECT_EQ(::write(master_, typed.data(), typed.size()), static_cast<ssize_t>(typed.size()));
    });
    const int rc = run_admin_command(args, web_, in, out_, err_, options_);
    typist.join();
    return rc;
  }

  int master_ = -1;
  int slave_ = -1;
  termios before_{};
};

TEST_F(TerminalTest, AskedTwiceWithoutEchoAndRestored) {
  ASSERT_EQ(type_and_run({"user", "add", "op", "--role", "observer"}, "secret\nsecret\n"), 0)
      << err_.str();
  EXPECT_EQ(err_.str(), "New password for op: Again: added user op (observer) to " +
                            web_.users_file.string() + "\n");
  EXPECT_NE(users().check_password("op", "secret"), nullptr);
  termios after{};
  ASSERT_EQ(::tcgetattr(slave_, &after), 0);
  EXPECT_EQ(after.c_lflag, before_.c_lflag);
  // What the terminal showed: the newlines (ECHONL), never the password.
  char shown[256];
  ::fcntl(master_, F_SETFL, O_NONBLOCK);
  const ssize_t n = ::read(master_, shown, sizeof shown);
  ASSERT_GE(n, 0);
  EXPECT_EQ(std::string(shown, static_cast<std::size_t>(n)).find("secret"), std::string::npos);
}

TEST_F(TerminalTest, DifferentPasswordsChangeNothing) {
  EXPECT_EQ(type_and_run({"user", "add", "op", "--role", "observer"}, "secret\nsecrets\n"), 1);
  EXPECT_EQ(err_.str(),
            "New password for op: Again: cncd-web: the two passwords differ; nothing changed\n");
  EXPECT_FALSE(std::filesystem::exists(web_.users_file));
}

}  // namespace
}  // namespace cncd::web
