// A WebSocket client that asks and never reads cannot make cncd-web hold its answers without
// bound: past ServerLimits::ws_queue_bytes (64 MiB) queued to it, it is closed, what cncd-web
// holds for it stays within the limit, and other clients are served meanwhile.
#include <fstream>

#include "web_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// cncd-web's resident memory, bytes (VmRSS), or 0 when unknown.
std::size_t resident_bytes(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.starts_with("VmRSS:")) return std::stoull(line.substr(6)) * 1024;
  }
  return 0;
}

TEST_F(WebTest, AClientThatNeverReadsIsClosedAtItsQueueLimit) {
  // A zigzag nothing can be decimated away from: each answer carries every point.
  std::string text = "G21 G90 G0 X0 Y0 Z5\nG1 F3000\n";
  for (int i = 0; i < 40000; ++i) {
    text += "X" + std::to_string(i % 200) + ".5 Y" + std::to_string((i * 7) % 150) + " Z" +
            std::to_string(i % 3) + "\n";
  }
  text += "M2\n";
  const auto program = programs_ / "zigzag.ngc";
  std::ofstream(program) << text;
  const json opened = client_.call("program.open", {{"path", program.string()}}, 60000);
  ASSERT_TRUE(opened.contains("result")) << opened.dump();

  const auto olga = cookie("olga");
  WsClient reader;
  ASSERT_EQ(reader.open(port_, {{"Cookie", olga}}), 101);
  const json params{{"tolerance", 1e-6}};
  const json first = reader.call("program.preview", params);
  ASSERT_TRUE(first.contains("result")) << first.dump().substr(0, 300);
  const std::size_t answer_bytes = first.dump().size();
  ASSERT_GT(answer_bytes, 500'000u) << "too small an answer to fill the queue soon";
  const std::size_t asks = (64u << 20) / answer_bytes + 1;

  // One ask at a time, so that cncd takes each answer as read (cncd-web reads it at once) and
  // only cncd-web's queue to the client grows. Meanwhile another client is answered.
  WsClient sink;
  ASSERT_EQ(sink.open(port_, {{"Cookie", olga}}), 101);
  std::size_t peak = 0;
  std::size_t asked = 0;
  const auto closed = [&] { return web_.log().find("bytes unread") != std::string::npos; };
  for (; asked < 2 * asks && !closed(); ++asked) {
    sink.send(json{{"jsonrpc", "2.0"},
                   {"id", static_cast<int>(asked + 1)},
                   {"method", "program.preview"},
                   {"params", params}});
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    if (asked % 10 == 0) {
      EXPECT_TRUE(reader.call("status.get").contains("result"));
    }
    peak = std::max(peak, resident_bytes(web_.pid()));
  }
  // cncd may still be working through the asks (a loaded machine answers late): twice the
  // limit is asked, so the close comes once they are answered.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!closed() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    peak = std::max(peak, resident_bytes(web_.pid()));
  }
  ASSERT_TRUE(closed()) << asked << " answers of " << answer_bytes << " bytes; log:\n"
                        << web_.log();
  // cncd-web's own count of what it held for the client when it closed it: the limit and at
  // most the one answer that crossed it. (Its resident size, which the allocator decides, is
  // only reported.)
  const std::string log = web_.log();
  const auto at = log.rfind(", ", log.find(" bytes unread"));
  const std::size_t unread = std::stoull(log.substr(at + 2));
  EXPECT_GT(unread, std::size_t{64} << 20);
  EXPECT_LE(unread, (std::size_t{64} << 20) + 2 * answer_bytes)
      << "cncd-web's resident size peaked at " << peak << " bytes";
  // What was sent before the close is readable, then the connection ends.
  int frames = 0;
  while (sink.read(10000))
    ++frames;
  EXPECT_LT(static_cast<std::size_t>(frames), asked);
  EXPECT_FALSE(sink.is_open());
  EXPECT_TRUE(reader.call("status.get").contains("result"));
}

}  // namespace
}  // namespace cncd::test
