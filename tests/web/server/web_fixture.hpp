// The real cncd on the simulated mill and the real cncd-web in front of it, on a free
// loopback port, with users made by `cncd-web user add`, a program directory of their own and
// a small page directory; helpers to log in and open WebSockets.
#pragma once

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "client.hpp"
#include "client_checks.hpp"
#include "daemon_process.hpp"
#include "web_client.hpp"

namespace cncd::test {

// A port nobody listens on now (the kernel's pick for a socket bound to port 0).
inline int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t length = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length);
  close(fd);
  return ntohs(addr.sin_port);
}

// cncd-web as a child process, its stderr in a file.
class WebProcess {
 public:
  ~WebProcess() { stop(); }
  // Starts it and waits until the port answers; "" or what went wrong (with its log).
  std::string start(const std::vector<std::string>& args, const std::filesystem::path& log,
                    int port) {
    log_ = log;
    pid_ = fork();
    if (pid_ == 0) {
      const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int in = open("/dev/null", O_RDONLY);
      dup2(in, STDIN_FILENO);
      dup2(out, STDOUT_FILENO);
      dup2(out, STDERR_FILENO);
      std::vector<char*> argv{const_cast<char*>(CNCD_WEB_BINARY)};
      for (const auto& a : args)
        argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        return "cncd-web exited:\n" + slurp(log_);
      }
      if (http_request(port, "GET", "/login.html").status != 0) return "";
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return "cncd-web did not answer within 20 s:\n" + slurp(log_);
  }
  // SIGTERM and wait: the exit status, 128 + signal when killed.
  int stop() {
    if (pid_ <= 0) return -1;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  std::string log() const { return slurp(log_); }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  std::filesystem::path log_;
};

class WebTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), machine_);
    programs_ = dir_.path() / "programs";
    outside_ = dir_.path() / "outside";
    www_ = dir_.path() / "www";
    std::filesystem::create_directories(programs_);
    std::filesystem::create_directories(outside_);
    std::filesystem::create_directories(www_);
    std::ofstream(www_ / "index.html") << "<!doctype html><title>cncd</title>";
    std::ofstream(www_ / "login.html") << "<!doctype html><title>login</title>";
    std::ofstream(www_ / "app.js") << "// the page";
    port_ = free_port();
    std::string text = slurp(ini_);
    const std::string dirs = "PROGRAM_DIRS = .\n";
    const std::string ours = "PROGRAM_DIRS = .:" + programs_.string() + "\n";
    if (const auto at = text.find(dirs); at != std::string::npos) {
      text.replace(at, dirs.size(), ours);
    } else {
      text.replace(text.find("[CNCD]\n"), 7, "[CNCD]\n" + ours);
    }
    text += "\n[WEB]\nPORT = " + std::to_string(port_) + "\nPROGRAM_DIR = " + programs_.string() +
            "\nUSERS_FILE = " + (dir_.path() / "web-users").string() +
            "\nMAX_UPLOAD_MB = 1\nJOG_HEARTBEAT = 0.25\n";
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
    for (const auto& [name, role] : {std::pair{"olga", "observer"},
                                     {"otto", "operator"},
                                     {"opal", "operator"},
                                     {"sam", "setter"},
                                     {"ada", "admin"}}) {
      ASSERT_EQ(add_user(name, role), 0);
    }
    ASSERT_EQ(
        web_.start({"--ini", ini_.string(), "--socket", daemon_.socket(), "--www", www_.string()},
                   dir_.path() / "cncd-web.log", port_),
        "");
  }

  void TearDown() override {
    EXPECT_EQ(web_.stop(), 0) << web_.log();
    if (HasFailure()) std::cerr << "cncd-web's log:\n" << web_.log();
  }

  // `cncd-web user add NAME --role ROLE`, the password (NAME + "-pw") on standard input.
  int add_user(const std::string& name, const std::string& role) {
    BackgroundCommand add(
        {CNCD_WEB_BINARY, "--ini", ini_.string(), "user", "add", name, "--role", role});
    add.write_stdin(password(name) + "\n");
    const auto result = add.wait();
    EXPECT_EQ(result.exit_status, 0) << result.err;
    return result.exit_status;
  }
  static std::string password(const std::string& name) { return name + "-pw"; }

  HttpReply login(const std::string& user, const std::string& pw) {
    return http_request(port_, "POST", "/api/login",
                        nlohmann::json{{"user", user}, {"password", pw}}.dump(),
                        {{"Content-Type", "application/json"}});
  }
  // The Cookie header of a fresh login of `user`.
  std::string cookie(const std::string& user) {
    const auto reply = login(user, password(user));
    EXPECT_EQ(reply.status, 200) << reply.body;
    const auto set = reply.header("set-cookie");
    return set.substr(0, set.find(';'));
  }
  // A WebSocket logged in as `user`.
  std::unique_ptr<WsClient> ws(const std::string& user) {
    auto client = std::make_unique<WsClient>();
    EXPECT_EQ(client->open(port_, {{"Cookie", cookie(user)}}), 101);
    return client;
  }
  std::string origin() const { return "http://127.0.0.1:" + std::to_string(port_); }

  nlohmann::json status() {
    const auto answer = client_.call("status.get", nullptr, 30000);
    EXPECT_TRUE(answer.contains("result")) << answer.dump();
    return answer.value("result", nlohmann::json());
  }
  template <typename Predicate>
  nlohmann::json wait_until(Predicate done, std::chrono::seconds limit = std::chrono::seconds(60)) {
    return poll_status([this] { return status(); }, done, limit);
  }

  TempDir dir_;
  std::filesystem::path ini_;
  std::string machine_ = "sim_mm";  // the example INI the daemon and cncd-web run
  std::filesystem::path programs_;
  std::filesystem::path outside_;
  std::filesystem::path www_;
  int port_ = 0;
  DaemonProcess daemon_;
  daemon::Client client_;
  WebProcess web_;
};

inline int code_of(const nlohmann::json& answer) {
  return answer.is_object() && answer.contains("error") ? answer["error"].value("code", 0) : 0;
}

}  // namespace cncd::test
