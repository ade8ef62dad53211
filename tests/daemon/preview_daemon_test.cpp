// program.preview in the real daemon: the open program's toolpath with the extents
// cncd-check gives, kept for the next ask; refused with no program
// open; cancelled when another program is opened; and a stop is never held up by it.
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>

#include "daemon_peer.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// A 3D surface of `rows` x `columns` feed moves, 0.15 mm apart.
std::string surface(int rows, int columns) {
  std::string text = "G21 G90 G94 G64 P0.01\nG0 Z5\nG0 X0 Y0\nG1 Z0 F1000\n";
  char line[96];
  for (int r = 0; r < rows; ++r) {
    for (int k = 0; k < columns; ++k) {
      const int c = r % 2 == 0 ? k : columns - 1 - k;
      const double x = c * 0.15;
      const double y = r * 0.15;
      std::snprintf(line, sizeof line, "X%.4f Y%.4f Z%.4f\n", x, y,
                    -3 + 2 * std::sin(x / 12) * std::cos(y / 9));
      text += line;
    }
  }
  return text + "G0 Z5\nM2\n";
}

class PreviewDaemon : public MachineTest {
 protected:
  void open(const std::filesystem::path& program) {
    result_of(call("program.open", {{"path", program.string()}}));
  }
};

TEST_F(PreviewDaemon, TheOpenProgramsPathHasCncdChecksExtentsAndIsKeptForTheNextAsk) {
  const auto program = dir_.write("g81.ngc",
                                  "G21 G17 G90 G94\nF100\nG0 X1 Y2 Z3\nG90 G81 G98 X4 Y5 Z1.5 "
                                  "R2.8\nG80\nM2\n");
  EXPECT_EQ(error_code(call("program.preview")), 1001);  // nothing open yet
  open(program);
  const json preview = result_of(call("program.preview"));
  EXPECT_EQ(preview["path"], std::filesystem::canonical(program).string());
  EXPECT_EQ(preview["complete"], true);
  EXPECT_EQ(preview["tolerance_asked"], 0.01);
  EXPECT_EQ(preview["kinds"], json({"rapid", "feed", "arc", "cycle", "probe"}));
  EXPECT_EQ(preview["polylines"], 2);
  EXPECT_EQ(preview["points"], 6);
  const auto check = run_command({CNCD_CHECK_BINARY, "--preview", "--ini", ini_.string(),
                                  "--state-dir", dir_.path().string(), program.string()});
  ASSERT_EQ(check.exit_status, 0) << check.err;
  EXPECT_EQ(preview["extents"], json::parse(check.out)["extents"]);
  EXPECT_EQ(preview["xyz"], json::parse(check.out)["xyz"]);
  // Asked again: the same answer, kept.
  EXPECT_EQ(result_of(call("program.preview")), preview);
  // Another tolerance is another preview.
  EXPECT_EQ(result_of(call("program.preview", {{"tolerance", 0.5}}))["tolerance_asked"], 0.5);
  EXPECT_EQ(error_code(call("program.preview", {{"tolerance", 0}})), -32602);
}

TEST_F(PreviewDaemon, ABatchMayNotAskForAPreview) {
  open(dir_.write("line.ngc", "G21 G90\nG1 X10 Y5 F500\nM2\n"));
  client_.send_raw(R"([{"jsonrpc":"2.0","id":1,"method":"program.preview"},)"
                   R"({"jsonrpc":"2.0","id":2,"method":"status.get"}])"
                   "\n");
  const json batch = json::parse(client_.read_line());
  ASSERT_TRUE(batch.is_array()) << batch.dump();
  EXPECT_EQ(batch[0]["error"]["code"], -32600) << batch.dump();
}

TEST_F(PreviewDaemon, AStopIsAnsweredWhileALargePreviewIsWorkedOut) {
  ready_machine();
  open(dir_.write("surface.ngc", surface(200, 500)));
  // The preview is asked for on a connection of its own and not waited for.
  const int asker = raw_connect(daemon_.socket());
  ASSERT_GE(asker, 0);
  const std::string ask = R"({"jsonrpc":"2.0","id":7,"method":"program.preview"})"
                          "\n";
  ASSERT_EQ(::write(asker, ask.data(), ask.size()), static_cast<ssize_t>(ask.size()));
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 20}}));
  result_of(call("machine.estop"));
  // Events (the estop's) come to every connection; the answer is the line with the id.
  std::string answer = received(asker);
  EXPECT_EQ(answer.find(R"("id":7)"), std::string::npos) << "answered before the estop";
  EXPECT_EQ(status()["state"], "estop");
  // The preview still comes, whole.
  char buffer[65536];
  const auto answered = [&answer] {
    const auto at = answer.find(R"({"id":7)");
    return at != std::string::npos && answer.find('\n', at) != std::string::npos;
  };
  while (!answered()) {
    pollfd ready{asker, POLLIN, 0};
    ASSERT_EQ(::poll(&ready, 1, 120'000), 1) << "no preview within 120 s";
    const ssize_t n = ::read(asker, buffer, sizeof buffer);
    ASSERT_GT(n, 0);
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(asker);
  const auto at = answer.find(R"({"id":7)");
  answer = answer.substr(at, answer.find('\n', at) - at);
  const json reply = json::parse(answer);
  ASSERT_TRUE(reply.contains("result")) << reply.dump();
  const json preview = reply["result"];
  EXPECT_EQ(preview["complete"], true);
  EXPECT_GT(preview["source_points"].get<int>(), 100'000);
  EXPECT_LT(preview["points"].get<int>(), 50'000);
  EXPECT_EQ(preview["extents"]["X"], json({0.0, 74.85}));
}

TEST_F(PreviewDaemon, OpeningAnotherProgramCancelsTheOneWaitedFor) {
  open(dir_.write("surface.ngc", surface(200, 500)));
  const int asker = raw_connect(daemon_.socket());
  ASSERT_GE(asker, 0);
  const std::string ask = R"({"jsonrpc":"2.0","id":8,"method":"program.preview"})"
                          "\n";
  ASSERT_EQ(::write(asker, ask.data(), ask.size()), static_cast<ssize_t>(ask.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  open(dir_.write("small.ngc", "G21 G90\nG1 X3 F500\nM2\n"));
  std::string lines;
  while (lines.find(R"("id":8)") == std::string::npos || lines.back() != '\n') {
    pollfd ready{asker, POLLIN, 0};
    ASSERT_EQ(::poll(&ready, 1, 30'000), 1) << lines;
    lines += received(asker);
  }
  ::close(asker);
  // The line with the id: {"error":...,"id":8,...}.
  const auto id = lines.find(R"("id":8)");
  const auto at = lines.rfind('\n', id) == std::string::npos ? 0 : lines.rfind('\n', id) + 1;
  const json answer = json::parse(lines.substr(at, lines.find('\n', id) - at));
  EXPECT_EQ(answer["error"]["code"], 1009) << answer.dump();
  // The start is no target of the program: X reaches 3 only.
  EXPECT_EQ(result_of(call("program.preview"))["extents"]["X"], json({3.0, 3.0}));
}

}  // namespace
}  // namespace cncd::test
