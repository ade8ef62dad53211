// /ws against the real daemon: roles (also for a hand-forged request and inside a batch), the
// WebSocket's Origin, the control lease, jogs stopped when a WebSocket goes, estop for all.
#include <fstream>
#include <map>

#include "web_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr int kRoleRefused = 1020;
constexpr int kLeaseRefused = 1021;

bool has_result(const json& answer) {
  return answer.is_object() && answer.contains("result");
}

class WebWsTest : public WebTest {
 protected:
  // Out of estop, on and homed, through `ws` (which must hold the lease).
  void ready_machine(WsClient& ws) {
    ASSERT_TRUE(has_result(ws.call("machine.reset")));
    ASSERT_TRUE(has_result(ws.call("machine.on")));
    const auto home = ws.call("machine.home");
    ASSERT_TRUE(has_result(home)) << home.dump();
    wait_until([](const json& s) {
      for (const auto& h : s["homed"]) {
        if (!h.get<bool>()) return false;
      }
      return s["motion"] == "idle";
    });
  }
};

TEST_F(WebWsTest, ObserverReadsButCannotCommand) {
  auto ws = this->ws("olga");
  const auto status = ws->call("status.get");
  ASSERT_TRUE(has_result(status)) << status.dump();
  EXPECT_TRUE(status["result"].contains("state"));
  for (const auto& [method, params] : {std::pair<std::string, json>{"machine.on", nullptr},
                                       {"machine.reset", nullptr},
                                       {"program.run", nullptr},
                                       {"jog.start", {{"axis", "X"}, {"velocity", 1.0}}},
                                       {"mdi.execute", {{"line", "G0 X1"}}},
                                       {"lease.take", nullptr},
                                       {"files.delete", {{"name", "x.ngc"}}},
                                       {"users.list", nullptr}}) {
    const auto answer = ws->call(method, params);
    EXPECT_EQ(code_of(answer), kRoleRefused) << method << ": " << answer.dump();
  }
  EXPECT_EQ(status["result"]["state"], this->status()["state"]);
  EXPECT_EQ(this->status()["state"], "estop");
}

TEST_F(WebWsTest, ForgedRequestsAndBatchesAreCheckedOneByOne) {
  auto ws = this->ws("olga");
  // A batch hiding a command among reads; a duplicate "method" key hoping the daemon reads
  // another one than cncd-web checked.
  ws->send_text(R"([{"jsonrpc":"2.0","id":1,"method":"status.get"},)"
                R"({"jsonrpc":"2.0","id":2,"method":"machine.reset"},)"
                R"({"jsonrpc":"2.0","id":3,"method":"status.get","method":"machine.reset"},)"
                R"({"jsonrpc":"2.0","method":"machine.reset"}])");
  std::map<int, json> answers;
  for (int frames = 0; frames < 10 && answers.size() < 3; ++frames) {
    const auto frame = ws->read();
    ASSERT_TRUE(frame) << "answers so far: " << answers.size();
    if (!frame->is_array()) continue;
    for (const auto& item : *frame)
      answers[item["id"].get<int>()] = item;
  }
  ASSERT_EQ(answers.size(), 3u);
  EXPECT_TRUE(has_result(answers[1])) << answers[1].dump();
  EXPECT_EQ(code_of(answers[2]), kRoleRefused);
  EXPECT_EQ(code_of(answers[3]), kRoleRefused);  // checked as what would be forwarded
  const auto later = ws->call("status.get");
  EXPECT_EQ(later["result"]["state"], "estop") << "no reset went through";
  // Unknown to the role table: never forwarded.
  EXPECT_EQ(code_of(ws->call("system.shutdown")), -32601);
  EXPECT_EQ(ws->read(500), std::nullopt) << "nothing else answered";
}

TEST_F(WebWsTest, WrongOriginIsRefused) {
  WsClient evil;
  EXPECT_EQ(evil.open(port_, {{"Cookie", cookie("otto")}, {"Origin", "http://evil.example"}}), 403);
  WsClient own;
  EXPECT_EQ(own.open(port_, {{"Cookie", cookie("otto")}, {"Origin", origin()}}), 101);
  EXPECT_TRUE(has_result(own.call("status.get")));
}

TEST_F(WebWsTest, MotionNeedsTheLeaseWhichIsTakenOverExplicitly) {
  auto otto = ws("otto");
  auto opal = ws("opal");
  EXPECT_EQ(code_of(otto->call("machine.home")), kLeaseRefused);
  ASSERT_TRUE(has_result(otto->call("lease.take")));
  EXPECT_EQ(opal->call("lease.get")["result"]["user"], "otto");
  EXPECT_EQ(code_of(opal->call("mdi.execute", {{"line", "G0 X1"}})), kLeaseRefused);
  EXPECT_EQ(code_of(opal->call("lease.take")), kLeaseRefused);
  // Stopping needs no lease.
  EXPECT_TRUE(has_result(opal->call("program.abort"))) << "abort is never refused the lease";
  const auto forced = opal->call("lease.take", {{"force", true}});
  ASSERT_TRUE(has_result(forced)) << forced.dump();
  EXPECT_EQ(forced["result"]["user"], "opal");
  EXPECT_EQ(code_of(otto->call("machine.home")), kLeaseRefused);
  // otto heard of the takeover.
  bool told = false;
  for (const auto& n : otto->notifications())
    told |= n.value("method", "") == "lease.changed" && n["params"].value("user", "") == "opal";
  EXPECT_TRUE(told);
  // The holder's last WebSocket closes: the lease is free again.
  opal->close();
  json holder;
  for (int i = 0; i < 100; ++i) {
    holder = otto->call("lease.get")["result"];
    if (holder.is_null()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(holder.is_null()) << holder.dump();
  EXPECT_TRUE(has_result(otto->call("lease.take")));
}

TEST_F(WebWsTest, ClosingMidJogStopsTheJog) {
  auto otto = ws("otto");
  ASSERT_TRUE(has_result(otto->call("lease.take")));
  ready_machine(*otto);
  const auto jog = otto->call("jog.start", {{"axis", "X"}, {"velocity", 5.0}});
  ASSERT_TRUE(has_result(jog)) << jog.dump();
  wait_until([](const json& s) { return s["velocity"].get<double>() > 0.0; });
  const double x = status()["position"]["commanded"]["x"];
  otto->drop();  // a browser killed: no close frame
  const auto stopped = wait_until(
      [](const json& s) { return s["velocity"].get<double>() == 0.0 && s["motion"] == "idle"; });
  EXPECT_GE(stopped["position"]["commanded"]["x"].get<double>(), x);
  EXPECT_LT(stopped["position"]["commanded"]["x"].get<double>(), 290.0)
      << "stopped by the drop, not the limit";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(status()["position"]["commanded"]["x"], stopped["position"]["commanded"]["x"]);
}

TEST_F(WebWsTest, AJogWithoutHeartbeatsStopsWhileTheWebSocketStaysOpen) {
  auto otto = ws("otto");
  ASSERT_TRUE(has_result(otto->call("lease.take")));
  ready_machine(*otto);
  ASSERT_TRUE(has_result(otto->call("jog.start", {{"axis", "X"}, {"velocity", 5.0}})));
  // Held: heartbeats every 100 ms keep it going past several heartbeat periods (0.25 s).
  for (int i = 0; i < 10; ++i) {
    const auto beat = otto->call("jog.heartbeat");
    ASSERT_TRUE(has_result(beat)) << beat.dump();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_GT(status()["velocity"].get<double>(), 0.0);
  // The page froze: no more heartbeats, the WebSocket still open.
  const auto stopped = wait_until(
      [](const json& s) { return s["velocity"].get<double>() == 0.0 && s["motion"] == "idle"; },
      std::chrono::seconds(10));
  EXPECT_LT(stopped["position"]["commanded"]["x"].get<double>(), 290.0);
  EXPECT_TRUE(has_result(otto->call("status.get")));
}

TEST_F(WebWsTest, EstopWithoutTheLease) {
  auto otto = ws("otto");
  auto opal = ws("opal");
  ASSERT_TRUE(has_result(otto->call("lease.take")));
  ASSERT_TRUE(has_result(otto->call("machine.reset")));
  wait_until([](const json& s) { return s["state"] != "estop"; });
  const auto estop = opal->call("machine.estop");
  EXPECT_TRUE(has_result(estop)) << estop.dump();
  wait_until([](const json& s) { return s["state"] == "estop"; });
  // An observer may stop the machine too.
  ASSERT_TRUE(has_result(otto->call("machine.reset")));
  EXPECT_TRUE(has_result(ws("olga")->call("machine.estop")));
  wait_until([](const json& s) { return s["state"] == "estop"; });
}

TEST_F(WebWsTest, ProgramOpenTakesANameInTheProgramDirectory) {
  auto sam = ws("sam");
  std::ofstream(programs_ / "p.ngc") << "G0 X1\nM2\n";
  const auto opened = sam->call("files.open", {{"name", "p.ngc"}});
  ASSERT_TRUE(has_result(opened)) << opened.dump();
  wait_until([&](const json& s) {
    return s["program"]["path"] == (std::filesystem::canonical(programs_) / "p.ngc").string();
  });
  EXPECT_EQ(code_of(sam->call("program.open", {{"path", "missing.ngc"}})), -32602);
}

TEST_F(WebWsTest, AnAdminAddsAUserAndChangesAPasswordAlone) {
  auto ada = ws("ada");
  // Hashed away from the thread that serves the WebSockets; answered when done.
  const auto added =
      ada->call("users.add", {{"name", "nina"}, {"role", "operator"}, {"password", "nina-pw"}});
  ASSERT_TRUE(has_result(added)) << added.dump();
  EXPECT_EQ(login("nina", "nina-pw").status, 200);
  EXPECT_EQ(code_of(ada->call("users.add",
                              {{"name", "nina"}, {"role", "operator"}, {"password", "x-pw-x"}})),
            -32602);
  const auto changed = ada->call("users.passwd", {{"name", "nina"}, {"password", "nina-new"}});
  ASSERT_TRUE(has_result(changed)) << changed.dump();
  EXPECT_EQ(login("nina", "nina-pw").status, 401);
  EXPECT_EQ(login("nina", "nina-new").status, 200);
  // Not inside a batch, where its answer could not wait for the hash.
  ada->send(json::array({{{"jsonrpc", "2.0"},
                          {"id", 7},
                          {"method", "users.passwd"},
                          {"params", {{"name", "nina"}, {"password", "nina-x"}}}}}));
  const auto batch = ada->read();
  ASSERT_TRUE(batch && batch->is_array()) << (batch ? batch->dump() : "no answer");
  EXPECT_EQ(code_of((*batch)[0]), -32600) << batch->dump();
  EXPECT_EQ(login("nina", "nina-new").status, 200);
}

// One hand on the machine: while the panel's MPG jogs at the machine, the page sees who holds
// manual motion and control is not taken from the web; once it rests, it is.
class WebPanelTest : public WebWsTest {
 protected:
  WebPanelTest() { machine_ = "sim_panel_mill"; }
  void sim_set(const std::string& signal, const json& value) {
    const auto answer = client_.call("sim.set", {{"signal", signal}, {"value", value}}, 30000);
    ASSERT_TRUE(has_result(answer)) << answer.dump();
  }
};

TEST_F(WebPanelTest, ControlIsNotTakenFromTheWebWhileThePanelsMpgJogs) {
  // The example's rapid knob stands at 0 V: turned up, or the MPG does not move. A quarter
  // turn keeps the jog below going for seconds, however slow a loaded machine is to look.
  ASSERT_NO_FATAL_FAILURE(sim_set("rapid_override_analog", 2.5));
  for (const char* method : {"machine.reset", "machine.on", "machine.home"}) {
    const auto answer = client_.call(method, nullptr, 30000);
    ASSERT_TRUE(has_result(answer)) << method << ": " << answer.dump();
  }
  wait_until([](const json& s) { return s["homed"][0] == true && s["motion"] == "idle"; });
  for (const char* signal : {"mpg_enable", "mpg_axis_x", "mpg_step_100"})
    ASSERT_NO_FATAL_FAILURE(sim_set(signal, 1));
  // Counts before the switches are taken (debounced) would be dropped.
  wait_until([](const json& s) {
    const auto& in = s["panel"]["inputs"];
    return in["MPG_ENABLE"] == true && in["MPG_AXIS_X"] == true && in["MPG_STEP_100"] == true &&
           s["overrides"]["rapid"] == 0.25;
  });
  auto otto = ws("otto");  // logged in before: a login hashes a password
  // 2500 detents of 0.1 mm: 250 mm of X at a quarter of the rapid speed, about five seconds.
  ASSERT_NO_FATAL_FAILURE(sim_set("mpg_counts", 250000));
  wait_until([](const json& s) { return s["panel"]["mpg"]["jogging"] == true; });
  const json seen = otto->call("status.get")["result"]["manual_holder"];
  EXPECT_EQ(seen,
            json({{"by", "the panel's MPG"}, {"panel", true}, {"axis", "X"}, {"joint", nullptr}}));
  // cncd-web hears of it within its status interval.
  json refused;
  for (int i = 0; i < 100 && !refused.contains("error"); ++i) {
    refused = otto->call("lease.take", {{"force", true}});
    if (has_result(refused)) {
      otto->call("lease.release");
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ASSERT_EQ(code_of(refused), kLeaseRefused) << refused.dump();
  EXPECT_EQ(refused["error"]["message"],
            "the panel's MPG is jogging X at the machine: take control once it rests");
  wait_until([](const json& s) { return s["panel"]["mpg"]["jogging"] == false; });
  json taken;
  for (int i = 0; i < 100 && !has_result(taken); ++i) {
    taken = otto->call("lease.take");
    if (!has_result(taken)) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(has_result(taken)) << taken.dump();
  EXPECT_TRUE(otto->call("status.get")["result"]["manual_holder"].is_null());
}

}  // namespace
}  // namespace cncd::test
