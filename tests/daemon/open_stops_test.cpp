// program.open checks the program off the daemon's loop: while one client's open is being
// checked, another client's stops (jog.stop, program.pause, program.abort, machine.off,
// machine.estop) are answered and take effect, before the open is answered. Each property is
// shown by order (status says the open is still pending), never by timing.
#include <signal.h>

#include <optional>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// Its check cannot end before its time budget (5 s): the program loops forever, moving.
constexpr const char* kEndless = "G21 G90\no100 while [1]\nG1 X1 F1000\nG1 X0\no100 endwhile\nM2\n";

// A client whose program.open is sent without waiting for the answer.
class PendingOpen {
 public:
  PendingOpen(const std::string& socket, const std::filesystem::path& program) {
    EXPECT_EQ(client_.connect(socket), "");
    client_.send_raw(json{{"jsonrpc", "2.0"},
                          {"id", 1},
                          {"method", "program.open"},
                          {"params", {{"path", program.string()}}}}
                         .dump() +
                     "\n");
  }
  // True once the answer has come (notifications are skipped).
  bool answered(int wait_ms = 1) {
    while (!answer_) {
      const auto line = client_.try_read_line(wait_ms);
      if (!line) return false;
      json message = json::parse(*line, nullptr, false);
      if (message.is_object() && message.contains("id")) answer_ = std::move(message);
    }
    return true;
  }
  json answer() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!answered(100) && std::chrono::steady_clock::now() < deadline) {
    }
    return answer_.value_or(json());
  }

 private:
  daemon::Client client_;
  std::optional<json> answer_;
};

class OpenStopsTest : public MachineTest {
 protected:
  // The open of `program` is still being checked and has not been answered.
  void expect_still_opening(PendingOpen& open, const std::filesystem::path& program,
                            const char* after) {
    EXPECT_EQ(status()["program"]["opening"], program.string()) << "after " << after;
    EXPECT_FALSE(open.answered()) << "after " << after;
  }
  double x(const json& s) { return s["position"]["commanded"]["x"].get<double>(); }
};

TEST_F(OpenStopsTest, JogStopAndEstopTakeEffectWhileAProgramIsChecked) {
  ready_machine();
  const auto endless = dir_.write("endless.ngc", kEndless);
  PendingOpen open(daemon_.socket(), endless);
  wait_until([&](const json& s) { return s["program"]["opening"] == endless.string(); });

  // A jog started meanwhile stops within its stopping distance once jog.stop has answered.
  constexpr double kVelocity = 50;  // mm/s; [AXIS_X] MAX_ACCELERATION 2000 mm/s^2
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", kVelocity}}));
  wait_until([&](const json& s) { return x(s) > 5; });
  result_of(call("jog.stop", {{"axis", "X"}}));
  const double at_stop = x(status());
  const json stopped = wait_until([](const json& s) { return s["motion"] == "idle"; });
  const double stopping_distance = kVelocity * kVelocity / (2 * 2000.0) + kVelocity * 0.001;
  EXPECT_LE(x(stopped) - at_stop, stopping_distance + 1e-9);
  expect_still_opening(open, endless, "jog.stop");

  result_of(call("machine.estop"));
  EXPECT_EQ(status()["state"], "estop");
  // The estop cancels the open, which says so.
  const json answer = open.answer();
  EXPECT_EQ(error_code(answer), 1009) << answer.dump();
  EXPECT_NE(answer["error"].value("message", "").find("machine.estop"), std::string::npos)
      << answer.dump();
  const json s = status();
  EXPECT_EQ(s["program"]["opening"], "");
  EXPECT_EQ(s["program"]["path"], "");
}

TEST_F(OpenStopsTest, PauseAbortAndOffTakeEffectWhileAProgramIsChecked) {
  ready_machine();
  const auto endless = dir_.write("endless.ngc", kEndless);
  PendingOpen open(daemon_.socket(), endless);
  wait_until([&](const json& s) { return s["program"]["opening"] == endless.string(); });

  // An MDI move runs meanwhile (program.run waits for the open; MDI does not).
  daemon::Client mdi;
  ASSERT_EQ(mdi.connect(daemon_.socket()), "");
  mdi.send_raw(
      R"({"jsonrpc":"2.0","id":7,"method":"mdi.execute","params":{"line":"G1 X100 F3000"}})"
      "\n");
  wait_until([&](const json& s) { return s["motion"] == "moving" && x(s) > 1; });
  result_of(call("program.pause"));
  json s = wait_until([](const json& st) { return st["motion"] == "paused"; });
  EXPECT_EQ(s["exec"], "paused");
  const double held = x(s);
  expect_still_opening(open, endless, "program.pause");
  EXPECT_EQ(x(status()), held);

  result_of(call("program.abort"));  // answers at rest
  s = status();
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["motion"], "idle");
  const json mdi_answer = json::parse(mdi.read_line(10000));
  EXPECT_EQ(mdi_answer["id"], 7);
  EXPECT_TRUE(mdi_answer.contains("error")) << mdi_answer.dump();
  expect_still_opening(open, endless, "program.abort");

  result_of(call("machine.off"));
  EXPECT_EQ(status()["state"], "off");
  expect_still_opening(open, endless, "machine.off");

  result_of(call("machine.estop"));
  EXPECT_EQ(error_code(open.answer()), 1009);
}

TEST_F(OpenStopsTest, ANewerOpenReplacesOneStillBeingChecked) {
  const auto endless = dir_.write("endless.ngc", kEndless);
  const auto small = dir_.write("small.ngc", "G21 G90\nG0 X1\nM2\n");
  PendingOpen first(daemon_.socket(), endless);
  wait_until([&](const json& s) { return s["program"]["opening"] == endless.string(); });
  // Run waits for the open's answer rather than run the program open before.
  const json run = call("program.run");
  EXPECT_EQ(error_code(run), 1004) << run.dump();
  EXPECT_NE(run["error"].value("message", "").find("still being checked"), std::string::npos)
      << run.dump();

  const json second = call("program.open", {{"path", small.string()}});
  EXPECT_EQ(result_of(second)["path"], small.string());
  const json answer = first.answer();
  EXPECT_EQ(error_code(answer), 1009) << answer.dump();
  EXPECT_NE(answer["error"].value("message", "").find("replaced by a newer program.open"),
            std::string::npos)
      << answer.dump();
  const json s = status();
  EXPECT_EQ(s["program"]["path"], small.string());
  EXPECT_EQ(s["program"]["total_lines"], 3);
  EXPECT_EQ(s["program"]["opening"], "");
}

TEST_F(OpenStopsTest, ShutdownAnswersAnOpenStillBeingChecked) {
  const auto endless = dir_.write("endless.ngc", kEndless);
  PendingOpen open(daemon_.socket(), endless);
  wait_until([&](const json& s) { return s["program"]["opening"] == endless.string(); });
  daemon_.signal(SIGTERM);
  const json answer = open.answer();
  EXPECT_EQ(error_code(answer), 1009) << answer.dump();
  EXPECT_NE(answer["error"].value("message", "").find("shutting down"), std::string::npos)
      << answer.dump();
  EXPECT_EQ(daemon_.stop(), 0);
}

TEST_F(OpenStopsTest, OpenIsRefusedWhileJoggingAndInABatch) {
  ready_machine();
  const auto small = dir_.write("small.ngc", "G21 G90\nG0 X1\nM2\n");
  result_of(call("jog.start", {{"axis", "Y"}, {"velocity", 5}}));
  const json r = call("program.open", {{"path", small.string()}});
  EXPECT_EQ(error_code(r), 1004) << r.dump();
  EXPECT_NE(r["error"].value("message", "").find("jogging"), std::string::npos) << r.dump();
  result_of(call("jog.stop", {{"axis", "Y"}}));
  wait_until([](const json& s) { return s["motion"] == "idle"; });

  // An open answers when its check ends, which a batch's one answer cannot wait for.
  client_.send_raw(json::array({{{"jsonrpc", "2.0"},
                                 {"id", 1},
                                 {"method", "program.open"},
                                 {"params", {{"path", small.string()}}}}})
                       .dump() +
                   "\n");
  json batch;
  do {
    batch = json::parse(client_.read_line(10000));
  } while (!batch.is_array());
  EXPECT_EQ(batch[0]["error"]["code"], -32600) << batch.dump();
  EXPECT_EQ(result_of(call("program.open", {{"path", small.string()}}))["path"], small.string());
}

}  // namespace
}  // namespace cncd::test
