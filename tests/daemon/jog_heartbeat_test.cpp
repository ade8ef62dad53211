// jog.start with "heartbeat_s" in the real daemon: the jog runs while jog.heartbeat keeps coming
// from the connection that started it, and stops under control when it stops coming or that
// connection closes. A jog without heartbeat_s runs on, as cncctl's do. The bounds are loose:
// a jog that was not stopped would run on for many seconds to the soft limit.
#include <memory>
#include <thread>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

class JogHeartbeatTest : public MachineTest {
 protected:
  void SetUp() override {
    MachineTest::SetUp();
    ready_machine();
    ASSERT_EQ(jogger_->connect(daemon_.socket()), "");
  }
  // Starts X at 20 mm/s (15 s from 0 to its soft limit) on the jogger's connection.
  void start_jog(double heartbeat_s) {
    json params = {{"axis", "X"}, {"velocity", 20}};
    if (heartbeat_s > 0) params["heartbeat_s"] = heartbeat_s;
    result_of(jogger_->call("jog.start", params));
    ASSERT_EQ(status()["motion"], "jogging");
  }
  double x() { return status()["position"]["commanded"]["x"].get<double>(); }
  // How long until the machine is at rest (at most `limit`), as a second client sees it;
  // `meanwhile` runs between looks.
  template <typename Meanwhile>
  Clock::duration until_rest(std::chrono::seconds limit, Meanwhile meanwhile) {
    const auto start = Clock::now();
    while (Clock::now() - start < limit && status()["motion"] != "idle") {
      meanwhile();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return Clock::now() - start;
  }
  // The messages of the "jog" events so far.
  std::vector<std::string> jog_events() {
    std::vector<std::string> messages;
    const json listed = result_of(call("errors.list"));
    for (const auto& event : listed["events"]) {
      if (event["kind"] == "jog") messages.push_back(event["message"]);
    }
    return messages;
  }

  std::unique_ptr<daemon::Client> jogger_ = std::make_unique<daemon::Client>();
};

TEST_F(JogHeartbeatTest, HeartbeatsKeepItMovingAndItStopsWhenTheyStop) {
  start_jog(1.0);
  // Heartbeats every 50 ms for 2.5 s, well past the 1 s they must come within.
  const auto until = Clock::now() + std::chrono::milliseconds(2500);
  double before = x();
  while (Clock::now() < until) {
    EXPECT_EQ(result_of(jogger_->call("jog.heartbeat"))["axes"], json({"X"}));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(status()["motion"], "jogging");
  EXPECT_GT(x(), before + 20);
  EXPECT_EQ(result_of(jogger_->call("jog.heartbeat", {{"axis", "x"}}))["axes"], json({"X"}));
  EXPECT_EQ(result_of(jogger_->call("jog.heartbeat", {{"axis", "Y"}}))["axes"], json::array());
  // No more: at rest within the heartbeat and the deceleration (10 ms), with room to spare.
  const auto took = until_rest(std::chrono::seconds(10), [] {});
  EXPECT_LT(took, std::chrono::seconds(4));
  before = x();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(x(), before);
  EXPECT_EQ(status()["fault"], "");
  const auto events = jog_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("stopped: no jog.heartbeat came for 1 s"), std::string::npos)
      << events[0];
  // The jog stopped: a heartbeat keeps nothing now.
  EXPECT_EQ(result_of(jogger_->call("jog.heartbeat"))["axes"], json::array());
}

TEST_F(JogHeartbeatTest, ClosingTheConnectionThatStartedItStopsIt) {
  start_jog(5.0);
  jogger_.reset();
  const auto took = until_rest(std::chrono::seconds(10), [] {});
  // Well before the 5 s heartbeat.
  EXPECT_LT(took, std::chrono::seconds(3));
  const auto events = jog_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("stopped: the connection that started it closed"), std::string::npos)
      << events[0];
}

TEST_F(JogHeartbeatTest, AHeartbeatFromAnotherConnectionDoesNotKeepItAlive) {
  start_jog(1.0);
  const auto took = until_rest(std::chrono::seconds(10), [this] {
    EXPECT_EQ(result_of(call("jog.heartbeat"))["axes"], json::array());
  });
  EXPECT_LT(took, std::chrono::seconds(4));
}

TEST_F(JogHeartbeatTest, WithoutHeartbeatAJogRunsOnAfterItsConnectionCloses) {
  start_jog(0);
  jogger_.reset();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(status()["motion"], "jogging");
  result_of(call("jog.stop", {{"axis", "X"}}));
  until_rest(std::chrono::seconds(10), [] {});
  EXPECT_TRUE(jog_events().empty());
}

TEST_F(JogHeartbeatTest, AJogStoppedOrTakenOverIsNoLongerWatched) {
  start_jog(0.2);
  result_of(jogger_->call("jog.stop", {{"axis", "X"}}));
  // Taken over by a jog without heartbeat from another connection: that one runs on.
  start_jog(0.2);
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 20}}));
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  EXPECT_EQ(status()["motion"], "jogging");
  result_of(call("jog.stop", {{"axis", "X"}}));
  until_rest(std::chrono::seconds(10), [] {});
  EXPECT_TRUE(jog_events().empty());
}

TEST_F(JogHeartbeatTest, TheHeartbeatIsFrom50MsTo5S) {
  for (const double bad : {0.0, 0.04, 5.5}) {
    EXPECT_EQ(error_code(jogger_->call("jog.start",
                                       {{"axis", "X"}, {"velocity", 20}, {"heartbeat_s", bad}})),
              -32602);
  }
  EXPECT_EQ(error_code(jogger_->call("jog.heartbeat", {{"axis", "Q"}})), -32602);
  EXPECT_EQ(status()["motion"], "idle");
}

}  // namespace
}  // namespace cncd::test
