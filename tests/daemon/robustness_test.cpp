// Clients that misbehave on the socket: they leave mid-request, shut down their sending side
// after the request, or never read. None of it harms the daemon or other clients.
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// A bare connection, for what the blocking client cannot do.
class RawSocket {
 public:
  explicit RawSocket(const std::string& path)
      : fd_(socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
    connected_ = connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  }
  ~RawSocket() { close_now(); }
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;

  bool connected() const { return connected_; }
  // Sends what fits without waiting; returns the bytes sent.
  std::size_t send_some(const std::string& bytes) {
    const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    return n > 0 ? static_cast<std::size_t>(n) : 0;
  }
  void send_all(const std::string& bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      ASSERT_GT(n, 0);
      sent += static_cast<std::size_t>(n);
    }
  }
  void shutdown_sending() { ::shutdown(fd_, SHUT_WR); }
  void close_now() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  // Everything until the daemon closes the connection (or `limit` passes).
  std::string read_to_end(std::chrono::milliseconds limit) {
    std::string out;
    const auto deadline = std::chrono::steady_clock::now() + limit;
    char buffer[65536];
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, 100) <= 0) continue;
      const ssize_t n = ::read(fd_, buffer, sizeof buffer);
      if (n <= 0) return out;
      out.append(buffer, static_cast<std::size_t>(n));
    }
    ADD_FAILURE() << "the daemon kept the connection open";
    return out;
  }

 private:
  int fd_;
  bool connected_ = false;
};

std::string request(int id, const std::string& method, const json& params = nullptr) {
  json r = {{"jsonrpc", "2.0"}, {"id", id}, {"method", method}};
  if (!params.is_null()) r["params"] = params;
  return r.dump() + "\n";
}

std::vector<json> lines_of(const std::string& text) {
  std::vector<json> out;
  std::size_t start = 0;
  for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1) {
    if (end > start) out.push_back(json::parse(text.substr(start, end - start), nullptr, false));
  }
  return out;
}

TEST_F(MachineTest, AClientThatStopsSendingStillGetsItsAnswers) {
  ready_machine();
  // As `socat` or `nc -N` do: send the requests, shut down the sending side, read the answers.
  RawSocket script(daemon_.socket());
  ASSERT_TRUE(script.connected());
  script.send_all(request(1, "status.get", {{"fields", {"state"}}}) +
                  request(2, "mdi.execute", {{"line", "G21 G90 G1 F1200 X4"}}));
  script.shutdown_sending();
  const auto answers = lines_of(script.read_to_end(std::chrono::seconds(20)));
  ASSERT_EQ(answers.size(), 2u);
  EXPECT_EQ(answers[0]["result"]["state"], "on") << answers[0].dump();
  EXPECT_EQ(answers[1]["id"], 2) << answers[1].dump();
  EXPECT_EQ(answers[1]["result"]["ok"], true) << answers[1].dump();
  EXPECT_EQ(status()["position"]["commanded"]["x"], 4.0);
}

TEST_F(MachineTest, AClientLeavingMidRequestHarmsNothing) {
  ready_machine();
  {
    RawSocket half(daemon_.socket());
    half.send_all(R"({"jsonrpc":"2.0","id":1,"method":"machine.)");
  }
  {
    // Its MDI block still runs to its end; the answer goes nowhere.
    RawSocket gone(daemon_.socket());
    gone.send_all(request(1, "mdi.execute", {{"line", "G21 G90 G1 F600 X30"}}));
  }
  {
    RawSocket aborter(daemon_.socket());
    wait_until([](const json& s) { return s["motion"] == "moving"; });
    aborter.send_all(request(1, "program.abort"));
  }
  const json s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_EQ(s["state"], "on");
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["fault"], "");
  // The machine takes new work at once.
  mdi("G0 X1");
  EXPECT_EQ(status()["position"]["commanded"]["x"], 1.0);
}

TEST_F(MachineTest, AClientThatNeverReadsIsDisconnectedWithTheReason) {
  RawSocket lazy(daemon_.socket());
  ASSERT_TRUE(lazy.connected());
  // Each answer is a few kB: 10,000 of them pass the 4 MiB bound while this client reads
  // nothing. It sends until the daemon takes no more: nothing for 5 s (on a loaded machine the
  // daemon may not get to read for a second or more while its backlog is still within bounds),
  // or, once the daemon has logged the cut-off, nothing for 0.2 s: the daemon keeps the reason
  // for a reader for 5 s only.
  std::string burst;
  for (int i = 0; i < 10'000; ++i)
    burst += request(i, "status.get");
  std::size_t sent = 0;
  auto last_progress = std::chrono::steady_clock::now();
  const auto stalled = [&] {
    const auto idle = std::chrono::steady_clock::now() - last_progress;
    return idle >= std::chrono::seconds(5) ||
           (idle >= std::chrono::milliseconds(200) &&
            daemon_.log().find("control client not reading") != std::string::npos);
  };
  while (sent < burst.size() && !stalled()) {
    const std::size_t n = lazy.send_some(burst.substr(sent, 65536));
    if (n > 0) {
      sent += n;
      last_progress = std::chrono::steady_clock::now();
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  // Others are served meanwhile.
  EXPECT_EQ(status()["state"], "estop");
  const std::string rest = lazy.read_to_end(std::chrono::seconds(20));
  const auto last_newline = rest.rfind('\n', rest.size() - 2);
  const json notice = json::parse(rest.substr(last_newline + 1), nullptr, false);
  ASSERT_TRUE(notice.is_object()) << "last line: " << rest.substr(last_newline + 1, 200);
  EXPECT_EQ(notice.value("method", ""), "connection.closing") << notice.dump();
  EXPECT_NE(notice["params"].value("reason", "").find("backlog over 4 MiB"), std::string::npos);
  EXPECT_EQ(status()["state"], "estop");
}

TEST_F(MachineTest, ABurstFromOneClientDoesNotHoldUpAnother) {
  // 1 MiB of requests in one go: served a few at a time, between other clients' requests.
  std::string burst;
  while (burst.size() < (1u << 20) - 100)
    burst += request(1, "status.get");
  RawSocket greedy(daemon_.socket());
  ASSERT_TRUE(greedy.connected());
  std::size_t sent = 0;
  for (int tries = 0; tries < 100 && sent < burst.size(); ++tries) {
    sent += greedy.send_some(burst.substr(sent));
    if (sent < burst.size()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::chrono::steady_clock::duration slowest{};
  for (int i = 0; i < 20; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(status()["state"], "estop");
    slowest = std::max(slowest, std::chrono::steady_clock::now() - t0);
  }
  EXPECT_LT(slowest, std::chrono::milliseconds(1000));
}

}  // namespace
}  // namespace cncd::test
