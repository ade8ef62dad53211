// Status subscriptions, broadcast events and robustness against the real cncd process.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "client.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

class SubscriptionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto ini = copy_example_machine(dir_.path());
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini.string()}), "");
  }

  json next_notification(daemon::Client& client, const std::string& method) {
    for (;;) {
      const json message = json::parse(client.read_line(5000));
      if (message.value("method", "") == method) return message["params"];
    }
  }

  TempDir dir_;
  DaemonProcess daemon_;
};

TEST_F(SubscriptionTest, FirstUpdateIsFullThenOnlyChanges) {
  daemon::Client watcher;
  ASSERT_EQ(watcher.connect(daemon_.socket()), "");
  const json r = watcher.call("status.subscribe", {{"interval_ms", 20}});
  ASSERT_TRUE(r.contains("result")) << r.dump();
  const json first = next_notification(watcher, "status.update");
  EXPECT_TRUE(first["full"].get<bool>());
  EXPECT_EQ(first["changed"]["state"], "estop");
  EXPECT_TRUE(first["changed"].contains("position"));
  const auto seq = first["seq"].get<std::uint64_t>();

  daemon::Client commander;
  ASSERT_EQ(commander.connect(daemon_.socket()), "");
  commander.call("machine.reset");
  for (;;) {
    const json update = next_notification(watcher, "status.update");
    EXPECT_GT(update["seq"].get<std::uint64_t>(), seq);
    EXPECT_FALSE(update["full"].get<bool>());
    if (update["changed"].contains("state")) {
      EXPECT_EQ(update["changed"]["state"], "off");
      // Only what changed is sent: the position of an idle machine is not.
      EXPECT_FALSE(update["changed"].contains("position")) << update.dump();
      break;
    }
  }
}

TEST_F(SubscriptionTest, FieldListLimitsTheUpdate) {
  daemon::Client watcher;
  ASSERT_EQ(watcher.connect(daemon_.socket()), "");
  watcher.call("status.subscribe", {{"interval_ms", 10}, {"fields", {"state", "exec"}}});
  const json first = next_notification(watcher, "status.update");
  EXPECT_EQ(first["changed"].size(), 2u) << first.dump();
  const json bad = watcher.call("status.subscribe", {{"interval_ms", 10}, {"fields", {"nope"}}});
  EXPECT_EQ(bad["error"]["code"], -32602);
  const json fast = watcher.call("status.subscribe", {{"interval_ms", 1}});
  EXPECT_EQ(fast["error"]["code"], -32602);
}

TEST_F(SubscriptionTest, SlowReaderDoesNotHoldUpOthers) {
  daemon::Client slow;
  ASSERT_EQ(slow.connect(daemon_.socket()), "");
  slow.call("status.subscribe", {{"interval_ms", 10}});
  daemon::Client other;
  ASSERT_EQ(other.connect(daemon_.socket()), "");
  other.call("machine.reset");
  other.call("machine.on");
  // The slow client reads nothing for a while; the other one is answered throughout.
  const auto until = Clock::now() + std::chrono::milliseconds(1500);
  int answered = 0;
  while (Clock::now() < until) {
    const auto t0 = Clock::now();
    const json r = other.call("status.get", nullptr, 2000);
    ASSERT_TRUE(r.contains("result"));
    EXPECT_LT(Clock::now() - t0, std::chrono::milliseconds(1000));
    ++answered;
  }
  EXPECT_GT(answered, 10);
  // Updates to the slow client were coalesced, not queued: it still sees increasing sequence
  // numbers and the latest state.
  json update;
  std::uint64_t last_seq = 0;
  for (int i = 0; i < 50; ++i) {
    update = next_notification(slow, "status.update");
    EXPECT_GT(update["seq"].get<std::uint64_t>(), last_seq);
    last_seq = update["seq"];
    if (update["changed"].value("state", "") == "on") break;
  }
  EXPECT_EQ(update["changed"]["state"], "on") << update.dump();
}

TEST_F(SubscriptionTest, EveryClientSeesEveryError) {
  daemon::Client a;
  daemon::Client b;
  ASSERT_EQ(a.connect(daemon_.socket()), "");
  ASSERT_EQ(b.connect(daemon_.socket()), "");
  a.call("machine.reset");
  a.call("machine.on");
  a.call("machine.home");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // Opened, then changed on disk (program.open refuses it as it is now).
  const auto program = dir_.write("bad.ngc", "G21\nM2\n");
  a.call("program.open", {{"path", program.string()}});
  dir_.write("bad.ngc", "G21\nG1 X1 Y1\nM2\n");  // no feed rate
  a.call("program.run");
  for (daemon::Client* client : {&a, &b}) {
    json event;
    do {
      event = next_notification(*client, "event");
    } while (event["level"] != "error");
    EXPECT_EQ(event["kind"], "program");
    EXPECT_NE(event["message"].get<std::string>().find("bad.ngc:2"), std::string::npos)
        << event.dump();
  }
  const json listed = b.call("errors.list", {{"since", 0}})["result"];
  bool found = false;
  for (const auto& e : listed["events"])
    found = found || e["level"] == "error";
  EXPECT_TRUE(found) << listed.dump();
}

TEST_F(SubscriptionTest, OversizedRequestIsRefusedAndClosed) {
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon_.socket()), "");
  std::string big(2 << 20, 'x');
  try {
    client.send_raw(big);
  } catch (const std::exception&) {
    // The daemon may close before everything is sent.
  }
  const json reply = json::parse(client.read_line(5000));
  EXPECT_EQ(reply["error"]["code"], 1006);
  EXPECT_THROW(client.read_line(2000), std::runtime_error);
  // The daemon itself is fine.
  daemon::Client again;
  ASSERT_EQ(again.connect(daemon_.socket()), "");
  EXPECT_TRUE(again.call("status.get").contains("result"));
}

TEST_F(SubscriptionTest, SystemInfoDescribesTheMachine) {
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon_.socket()), "");
  const json info = client.call("system.info")["result"];
  EXPECT_EQ(info["protocol_version"], 1);
  EXPECT_EQ(info["machine"]["axes"], json({"X", "Y", "Z"}));
  EXPECT_EQ(info["machine"]["units"], "mm");
  // The sim mill's [AXIS_X] MIN_LIMIT and MAX_LIMIT, and its override bounds.
  const json& x_limits = info["machine"]["soft_limits"]["x"];
  EXPECT_EQ(x_limits, json({-10.0, 300.0})) << info.dump();
  EXPECT_EQ(info["machine"]["overrides"]["max_feed"], 1.5);
}

}  // namespace
}  // namespace cncd::test
