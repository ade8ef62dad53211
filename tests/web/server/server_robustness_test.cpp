// Bad input never stops cncd-web: random bytes, malformed and oversized requests, a header
// that never ends, hostile WebSocket frames. Seeded, so a failure repeats.
#include <random>

#include "web_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// The server still serves: a login works and its WebSocket answers.
void expect_alive(WebTest& test, int port, const std::string& cookie) {
  EXPECT_EQ(http_request(port, "GET", "/login.html").status, 200);
  WsClient ws;
  ASSERT_EQ(ws.open(port, {{"Cookie", cookie}}), 101);
  EXPECT_TRUE(ws.call("status.get").contains("result"));
  (void)test;
}

TEST_F(WebTest, RandomAndMalformedRequestsAreRefusedAndTheServerGoesOn) {
  const auto otto = cookie("otto");
  std::mt19937 random(24);
  for (int i = 0; i < 20; ++i) {
    std::string bytes(1 + random() % 2000, '\0');
    for (auto& b : bytes)
      b = static_cast<char>(random());
    raw_exchange(port_, bytes, 2000);
  }
  // A header over the limit, a request line with a huge target, a bad version, a body longer
  // than the request limit.
  const auto big_header =
      raw_exchange(port_, "GET / HTTP/1.1\r\nX: " + std::string(64 * 1024, 'a') + "\r\n\r\n", 5000);
  EXPECT_TRUE(big_header.text.starts_with("HTTP/1.1 431") || big_header.closed)
      << big_header.text.substr(0, 100);
  const auto bad_version = raw_exchange(port_, "GET / HTTP/9.9\r\n\r\n", 5000);
  EXPECT_TRUE(bad_version.text.starts_with("HTTP/1.1 400") || bad_version.closed);
  const auto big_body = http_request(port_, "POST", "/api/login", std::string(2 << 20, 'x'));
  EXPECT_TRUE(big_body.status == 413 || big_body.status == 0) << big_body.status;
  expect_alive(*this, port_, otto);
}

TEST_F(WebTest, AStalledHeaderIsCutOffAndHoldsUpNobody) {
  const auto otto = cookie("otto");
  // Starts a request and never finishes its header (slowloris); meanwhile others are served.
  std::thread slow([&] {
    const auto reply = raw_exchange(port_, "GET / HTTP/1.1\r\nHost: x\r\n", 60000);
    EXPECT_TRUE(reply.closed) << "the server should cut a header that never ends";
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  expect_alive(*this, port_, otto);
  slow.join();
}

TEST_F(WebTest, HostileWebSocketFramesAreAnsweredWithErrors) {
  const auto otto = cookie("otto");
  WsClient ws;
  ASSERT_EQ(ws.open(port_, {{"Cookie", otto}}), 101);
  const std::vector<std::string> frames = {
      "",
      "not json",
      "[]",
      "[1,2,3]",
      "{}",
      R"({"jsonrpc":"2.0","id":1})",
      R"({"jsonrpc":"2.0","id":{"a":1},"method":"status.get"})",
      R"({"jsonrpc":"2.0","id":2,"method":"program.open","params":{"path":7}})",
      R"({"jsonrpc":"2.0","id":3,"method":"program.open","params":[]})",
      R"({"jsonrpc":"2.0","id":4,"method":"files.rename","params":{"from":1}})",
      R"({"jsonrpc":"2.0","id":5,"method":"jog.start","params":"X"})",
      std::string(100000, '[') + std::string(100000, ']'),
      "[" + std::string(1000, '{') + "}"};
  for (const auto& frame : frames) {
    ws.send_text(frame);
    // Every frame but the notification-free empty batch gets some answer; none kills the link.
    ws.read(2000);
  }
  EXPECT_TRUE(ws.call("status.get").contains("result"));
  // A frame over the message limit (1 MiB) closes that WebSocket, and only it.
  ws.send_text(std::string(2 << 20, ' '));
  EXPECT_FALSE(ws.read(5000).has_value());
  expect_alive(*this, port_, otto);
}

}  // namespace
}  // namespace cncd::test
