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

// Asks for the preview under `id` on a connection of its own, without waiting; the descriptor.
int ask_preview(const std::string& socket, int id) {
  const int fd = raw_connect(socket);
  const std::string ask =
      R"({"jsonrpc":"2.0","id":)" + std::to_string(id) + R"(,"method":"program.preview"})" + "\n";
  if (fd >= 0 && ::write(fd, ask.data(), ask.size()) != static_cast<ssize_t>(ask.size())) return -1;
  return fd;
}

// The answer under `id` among the lines `fd` receives (events come to every connection), after
// `seen`, what was read from it already; null when none comes within `limit`.
json answer_to(int fd, int id, std::string seen, std::chrono::seconds limit) {
  const std::string key = R"("id":)" + std::to_string(id) + ",";
  const auto deadline = std::chrono::steady_clock::now() + limit;
  for (;;) {
    const auto at = seen.find(key);
    if (at != std::string::npos && seen.find('\n', at) != std::string::npos) {
      const auto start = seen.rfind('\n', at) == std::string::npos ? 0 : seen.rfind('\n', at) + 1;
      return json::parse(seen.substr(start, seen.find('\n', at) - start));
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd ready{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&ready, 1, static_cast<int>(left.count())) != 1) return nullptr;
    const std::string more = received(fd);
    if (more.empty()) return nullptr;  // the daemon closed the connection
    seen += more;
  }
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
  open(dir_.write("surface.ngc", surface(100, 200)));
  const int asker = ask_preview(daemon_.socket(), 7);
  ASSERT_GE(asker, 0);
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 20}}));
  result_of(call("machine.estop"));
  const std::string before = received(asker);
  EXPECT_EQ(before.find(R"("id":7,)"), std::string::npos) << "answered before the estop";
  EXPECT_EQ(status()["state"], "estop");
  // The preview still comes, whole.
  const json reply = answer_to(asker, 7, before, std::chrono::seconds(120));
  ::close(asker);
  ASSERT_TRUE(reply.contains("result")) << reply.dump();
  const json preview = reply["result"];
  EXPECT_EQ(preview["complete"], true);
  EXPECT_GT(preview["source_points"].get<int>(), 20'000);
  EXPECT_LT(preview["points"].get<int>(), 20'000);
  EXPECT_EQ(preview["extents"]["X"], json({0.0, 29.85}));
}

TEST_F(PreviewDaemon, OpeningAnotherProgramCancelsTheOneWaitedFor) {
  open(dir_.write("surface.ngc", surface(100, 200)));
  const int asker = ask_preview(daemon_.socket(), 8);
  ASSERT_GE(asker, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  open(dir_.write("small.ngc", "G21 G90\nG1 X3 F500\nM2\n"));
  const json answer = answer_to(asker, 8, "", std::chrono::seconds(30));
  ::close(asker);
  EXPECT_EQ(answer["error"]["code"], 1009) << answer.dump();
  // The start is no target of the program: X reaches 3 only.
  EXPECT_EQ(result_of(call("program.preview"))["extents"]["X"], json({3.0, 3.0}));
}

// `asks` requests for the open program's preview, ids 1 ..., one line each; at `tolerance`
// when it is given.
std::string preview_asks(int asks, const std::string& tolerance = "") {
  const std::string params =
      tolerance.empty() ? "" : R"(,"params":{"tolerance":)" + tolerance + "}";
  std::string requests;
  for (int id = 1; id <= asks; ++id) {
    requests += R"({"jsonrpc":"2.0","id":)" + std::to_string(id) +
                R"(,"method":"program.preview")" + params + "}\n";
  }
  return requests;
}

// What a client that sent preview asks got: the answers (each line with a result), their bytes
// with the newlines, whether the connection.closing notice came and whether the daemon closed.
struct Answered {
  int answers = 0;
  std::size_t bytes = 0;
  bool notice = false;
  bool closed = false;
};

// Counts the complete lines of `seen` into `got`, leaving an unfinished last line in `seen`.
void count_lines(std::string& seen, Answered& got) {
  std::size_t start = 0;
  for (std::size_t end; (end = seen.find('\n', start)) != std::string::npos; start = end + 1) {
    const std::string_view line(seen.data() + start, end - start);
    if (line.find(R"("result":)") != std::string_view::npos) {
      ++got.answers;
      got.bytes += line.size() + 1;
    } else if (line.find("connection.closing") != std::string_view::npos) {
      got.notice = true;
    }
  }
  seen.erase(0, start);
}

// Sends `requests` a little at a time on a non-blocking connection while reading every answer,
// until `expected` answers came, the daemon closed, or nothing came for `silence`.
Answered ask_while_reading(const std::string& socket, const std::string& requests, int expected,
                           std::chrono::milliseconds silence) {
  Answered got;
  const int fd = raw_connect(socket);
  if (fd < 0) return got;
  std::size_t sent = 0;
  std::string seen;
  while (got.answers < expected && !got.closed) {
    const bool sending = sent < requests.size();
    pollfd ready{fd, static_cast<short>(POLLIN | (sending ? POLLOUT : 0)), 0};
    if (::poll(&ready, 1, static_cast<int>(silence.count())) != 1) break;
    if (sending && (ready.revents & POLLOUT)) {
      const ssize_t n = ::send(fd, requests.data() + sent,
                               std::min<std::size_t>(requests.size() - sent, 200), MSG_NOSIGNAL);
      if (n > 0) sent += static_cast<std::size_t>(n);
    }
    char buffer[65536];
    ssize_t n;
    while ((n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT)) > 0)
      seen.append(buffer, static_cast<std::size_t>(n));
    got.closed = n == 0;
    count_lines(seen, got);
  }
  ::close(fd);
  return got;
}

// A client reading all the while gets every answer, however many it asks for: 100 asks for a
// kept preview of about 21 kB are 2,126,292 bytes, all of them answers.
TEST_F(PreviewDaemon, AClientThatReadsGetsAnAnswerToEveryAsk) {
  open(dir_.write("surface.ngc", surface(100, 200)));
  const std::string kept = result_of(call("program.preview")).dump();
  const Answered got =
      ask_while_reading(daemon_.socket(), preview_asks(100), 100, std::chrono::seconds(30));
  EXPECT_EQ(got.answers, 100);
  EXPECT_FALSE(got.notice);
  // Each answer is {"id":N,"jsonrpc":"2.0","result":PREVIEW}: 100 of them, and the digits of
  // the ids 1 to 100.
  const std::size_t answer = std::string(R"({"id":,"jsonrpc":"2.0","result":})").size() + 1;
  EXPECT_EQ(got.bytes, 100 * (answer + kept.size()) + 9 + 90 * 2 + 3);
  EXPECT_TRUE(call("status.get").contains("result"));
}

// Reads what `fd` receives until the daemon closes it or nothing comes for 30 s.
Answered read_to_the_end(int fd) {
  Answered got;
  std::string seen;
  for (pollfd ready{fd, POLLIN, 0}; !got.closed && ::poll(&ready, 1, 30'000) == 1;) {
    const std::string more = received(fd);
    got.closed = more.empty();
    seen += more;
    count_lines(seen, got);
  }
  return got;
}

// One that asks at once for far more than the backlog and only then reads (as cncd-web does
// when the machine is busy and the answers come together) gets every answer as it reads:
// the answers beyond the backlog wait for it, and its further asks wait in its socket.
TEST_F(PreviewDaemon, AClientThatAsksForMoreThanTheBacklogGetsItAllAsItReads) {
  open(dir_.write("surface.ngc", surface(200, 500)));
  const std::size_t kept = result_of(call("program.preview")).dump().size();
  ASSERT_GT(100 * kept, std::size_t{5} << 20);
  const int fd = raw_connect(daemon_.socket());
  ASSERT_GE(fd, 0);
  const std::string requests = preview_asks(100);
  ASSERT_EQ(send_for(fd, requests, std::chrono::seconds(10)), requests.size());
  ::shutdown(fd, SHUT_WR);  // the daemon closes once all is answered
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_TRUE(call("status.get").contains("result"));
  const Answered got = read_to_the_end(fd);
  ::close(fd);
  EXPECT_EQ(got.answers, 100);
  EXPECT_FALSE(got.notice);
  EXPECT_TRUE(got.closed);
}

// One that asks for more than it reads is cut off, and told so: never left waiting for
// answers that do not come, nor holding the daemon's memory. Each answer here is several MiB
// (nothing left out at a tolerance of 1e-6): past 32 MiB of them held, it is cut off.
TEST_F(PreviewDaemon, AClientThatAsksForMoreThanItReadsIsCutOffAndTold) {
  open(dir_.write("surface.ngc", surface(400, 500)));
  const std::size_t kept =
      result_of(client_.call("program.preview", {{"tolerance", 1e-6}}, 60000)).dump().size();
  ASSERT_GT(kept, std::size_t{3} << 20);
  const int fd = raw_connect(daemon_.socket());
  ASSERT_GE(fd, 0);
  const std::string requests = preview_asks(40, "0.000001");
  ASSERT_EQ(send_for(fd, requests, std::chrono::seconds(10)), requests.size());
  // The answers pile up unread until the daemon cuts the connection off.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const Answered got = read_to_the_end(fd);
  ::close(fd);
  EXPECT_TRUE(got.closed);
  EXPECT_TRUE(got.notice);
  EXPECT_LT(got.answers, 40);
  EXPECT_TRUE(call("status.get").contains("result"));
}

// A connection owed as many deferred answers as the daemon allows has its further requests
// wait, but a stop among them is acted on at once.
TEST_F(PreviewDaemon, AStopBehindManyOwedAnswersIsActedOnAtOnce) {
  ready_machine();
  open(dir_.write("surface.ngc", surface(300, 500)));
  const int fd = raw_connect(daemon_.socket());
  ASSERT_GE(fd, 0);
  const std::string requests =
      preview_asks(40, "0.000001") + R"({"jsonrpc":"2.0","id":99,"method":"machine.estop"})" + "\n";
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 20}}));
  ASSERT_EQ(send_for(fd, requests, std::chrono::seconds(10)), requests.size());
  const auto sent = std::chrono::steady_clock::now();
  while (status()["state"] != "estop" &&
         std::chrono::steady_clock::now() - sent < std::chrono::seconds(5)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(status()["state"], "estop");
  const json reply = answer_to(fd, 99, "", std::chrono::seconds(120));
  ::close(fd);
  EXPECT_EQ(reply["result"]["ok"], true) << reply.dump().substr(0, 300);
}

}  // namespace
}  // namespace cncd::test
