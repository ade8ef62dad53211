// The real cncd on the simulated mill and the real cncd-telemetry watching it.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <memory>
#include <regex>
#include <string>
#include <thread>

#include "../daemon/machine_fixture.hpp"

namespace cncd::test {

struct HttpAnswer {
  int status = 0;
  std::string body;
};

// Sends `request` as it is to 127.0.0.1:port and reads until the server closes; status 0 when
// the connection failed or no status line came.
// A TCP connection to 127.0.0.1:port whose reads give up after `timeout_s`; -1 when refused.
inline int connect_loopback(int port, int timeout_s = 10) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval timeout{timeout_s, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Whether the peer closes `fd` (a read returns end of file) before its read timeout.
inline bool closed_by_peer(int fd) {
  char byte;
  for (;;) {
    const ssize_t n = ::recv(fd, &byte, 1, 0);
    if (n == 0) return true;
    if (n < 0) return errno == ECONNRESET;  // else timed out: still open
  }
}

inline HttpAnswer http_exchange(int port, const std::string& request) {
  HttpAnswer answer;
  const int fd = connect_loopback(port);
  if (fd < 0) return answer;
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string raw;
  char buffer[65536];
  for (ssize_t n; (n = ::recv(fd, buffer, sizeof buffer, 0)) > 0;)
    raw.append(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  if (raw.rfind("HTTP/1.1 ", 0) == 0) answer.status = std::atoi(raw.c_str() + 9);
  if (const auto end = raw.find("\r\n\r\n"); end != std::string::npos)
    answer.body = raw.substr(end + 4);
  return answer;
}

class TelemetryTest : public MachineTest {
 protected:
  void SetUp() override {
    MachineTest::SetUp();
    start_telemetry();
  }
  void start_telemetry() {
    telemetry_ = std::make_unique<BackgroundCommand>(std::vector<std::string>{
        CNCD_TELEMETRY_BINARY, "--ini", ini_.string(), "--socket", daemon_.socket(),
        "--metrics-listen", "127.0.0.1:0", "--shdr-listen", "127.0.0.1:0"});
    const std::regex serving("serving /metrics on 127\\.0\\.0\\.1:([0-9]+)");
    const std::regex shdr("serving SHDR on 127\\.0\\.0\\.1:([0-9]+)");
    for (int i = 0; i < 2000 && (port_ == 0 || shdr_port_ == 0); ++i) {
      std::smatch m;
      const std::string err = telemetry_->err_so_far();
      if (std::regex_search(err, m, serving)) port_ = std::stoi(m[1]);
      if (std::regex_search(err, m, shdr)) shdr_port_ = std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_NE(port_, 0) << telemetry_->err_so_far();
    ASSERT_NE(shdr_port_, 0) << telemetry_->err_so_far();
  }
  HttpAnswer get(const std::string& target) {
    return http_exchange(
        port_, "GET " + target + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
  }
  std::string metrics() {
    const HttpAnswer a = get("/metrics");
    EXPECT_EQ(a.status, 200) << telemetry_->err_so_far();
    return a.body;
  }
  // Waits until /metrics holds a line starting with `prefix`, and returns the body then.
  std::string metrics_with(const std::string& line) {
    std::string body;
    for (int i = 0; i < 3000; ++i) {
      body = metrics();
      if (body.find("\n" + line) != std::string::npos) return body;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "no line '" << line << "' in:\n" << body;
    return body;
  }

  std::unique_ptr<BackgroundCommand> telemetry_;
  int port_ = 0;
  int shdr_port_ = 0;
};

}  // namespace cncd::test
