// MQTT from the real cncd-telemetry through a real mosquitto broker to a real subscriber.
#include <set>

#include "broker.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class MqttTest : public TelemetryTest {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists("/usr/sbin/mosquitto"))
      GTEST_SKIP() << "mosquitto is not installed (scripts/setup.sh --with-broker)";
    MachineTest::SetUp();
    ASSERT_EQ(broker_.start(), "");
    base_ini_ = slurp(ini_);
    configure_mqtt(broker_.port());
    start_telemetry();
  }
  // The machine's INI with cncd-telemetry publishing to a broker on `port`.
  void configure_mqtt(int port) {
    std::ofstream(ini_, std::ios::trunc)
        << base_ini_ << "\n[TELEMETRY]\nMACHINE_ID = mill-1\nMQTT_HOST = 127.0.0.1\n"
        << "MQTT_PORT = " << port << "\n";
  }
  // The events' seq numbers as they came, each once.
  static std::vector<std::uint64_t> event_seqs(const std::vector<Message>& messages) {
    std::vector<std::uint64_t> seqs;
    std::set<std::uint64_t> seen;
    for (const auto& m : messages) {
      if (m.topic != "cncd/mill-1/events") continue;
      const auto seq = json::parse(m.payload)["seq"].get<std::uint64_t>();
      if (seen.insert(seq).second) seqs.push_back(seq);
    }
    return seqs;
  }
  static void expect_no_gap(const std::vector<std::uint64_t>& seqs) {
    for (std::size_t i = 1; i < seqs.size(); ++i)
      EXPECT_EQ(seqs[i], seqs[i - 1] + 1) << "at " << i;
  }
  void run_part() {
    start_program("part.ngc", "G21 G90 F3000\n(MSG, first)\nG1 X5\n(MSG, second)\nG1 Y5\nM30\n");
    wait_until([](const json& s) { return s["exec"] == "idle" && s["program"]["result"] != ""; });
  }

  std::string base_ini_;
  TempDir broker_dir_;
  Broker broker_{broker_dir_.path()};
};

TEST_F(MqttTest, ANewSubscriberGetsTheRetainedStateAndAvailability) {
  // Give the first state time to go out before anyone listens.
  Subscriber early(broker_.port(), "cncd/mill-1/availability");
  ASSERT_TRUE(early.got("/availability", "online"));
  Subscriber late(broker_.port(), "cncd/mill-1/#");
  ASSERT_TRUE(late.got("/state", "\"estop\""));
  bool retained_state = false;
  bool retained_online = false;
  for (const auto& m : late.messages()) {
    retained_state |= m.topic == "cncd/mill-1/state" && m.retained;
    retained_online |= m.topic == "cncd/mill-1/availability" && m.retained && m.payload == "online";
  }
  EXPECT_TRUE(retained_state);
  EXPECT_TRUE(retained_online);
  const json state = json::parse(late.messages().back().payload, nullptr, false);
  ready_machine();
  EXPECT_TRUE(late.got("/state", "\"state\":\"on\""));
  EXPECT_TRUE(late.got("/position", "\"machine_position\""));
}

TEST_F(MqttTest, ARunGivesItsEventsInOrderAndOneJob) {
  Subscriber sub(broker_.port(), "cncd/mill-1/#");
  ASSERT_TRUE(sub.subscribed());
  ASSERT_TRUE(sub.got("/availability", "online"));
  ready_machine();
  run_part();
  ASSERT_TRUE(sub.got("/job", "\"result\":\"done\""));
  ASSERT_TRUE(sub.got("/events", "finished in"));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto messages = sub.messages();
  int jobs = 0;
  for (const auto& m : messages) {
    if (m.topic != "cncd/mill-1/job") continue;
    ++jobs;
    const json job = json::parse(m.payload);
    EXPECT_EQ(job["parts"], 1);
    EXPECT_EQ(job["machine"], "mill-1");
  }
  EXPECT_EQ(jobs, 1);
  const auto seqs = event_seqs(messages);
  ASSERT_GE(seqs.size(), 4u);  // started, first, second, finished
  expect_no_gap(seqs);
  EXPECT_TRUE(sub.got("/events", "first"));
  EXPECT_TRUE(sub.got("/events", "second"));
}

TEST_F(MqttTest, AKilledTelemetryLeavesItsLastWill) {
  Subscriber sub(broker_.port(), "cncd/mill-1/availability");
  ASSERT_TRUE(sub.got("/availability", "online"));
  ::kill(telemetry_->pid(), SIGKILL);
  telemetry_->wait();
  EXPECT_TRUE(sub.got("/availability", "offline", 30));
}

TEST_F(MqttTest, TenSecondsWithoutTheBrokerLoseNoEvent) {
  {
    Subscriber sub(broker_.port(), "cncd/mill-1/#");
    ASSERT_TRUE(sub.got("/availability", "online"));
  }
  ready_machine();
  const int port = broker_.port();
  broker_.stop();
  run_part();  // its events wait in cncd-telemetry
  run_part();
  std::this_thread::sleep_for(std::chrono::seconds(10));
  ASSERT_EQ(broker_.start(port), "");
  // The subscriber is back before cncd-telemetry, whose tries come further apart.
  Subscriber sub(port, "cncd/mill-1/#");
  ASSERT_TRUE(sub.subscribed());
  ASSERT_TRUE(sub.got("/availability", "online", 90));
  ASSERT_TRUE(sub.got("/job", "\"result\":\"done\"", 30));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto seqs = event_seqs(sub.messages());
  const json events = result_of(call("errors.list"))["events"];
  // Every event cncd logged from the first run's start on came through, in order.
  std::uint64_t first_run = 0;
  for (const auto& e : events) {
    if (first_run == 0 &&
        e["message"].get<std::string>().find("part.ngc started") != std::string::npos)
      first_run = e["seq"].get<std::uint64_t>();
  }
  ASSERT_NE(first_run, 0u);
  ASSERT_FALSE(seqs.empty());
  EXPECT_LE(seqs.front(), first_run);
  EXPECT_EQ(seqs.back(), events.back()["seq"].get<std::uint64_t>());
  expect_no_gap(seqs);
}

// A "broker" that takes the connection and never says a word: the machine is not held up.
TEST_F(MqttTest, ABrokerThatNeverAnswersHoldsNothingUp) {
  const int silent = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(silent, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(silent, 16), 0);
  socklen_t size = sizeof addr;
  ::getsockname(silent, reinterpret_cast<sockaddr*>(&addr), &size);
  telemetry_.reset();
  port_ = shdr_port_ = 0;
  configure_mqtt(ntohs(addr.sin_port));
  start_telemetry();
  ready_machine();
  run_part();
  start_program("long.ngc", "G21 G90 F100\nG1 X100\nM30\n");
  const auto before = std::chrono::steady_clock::now();
  result_of(call("machine.estop"));
  EXPECT_EQ(status()["state"], "estop");
  EXPECT_LT(std::chrono::steady_clock::now() - before, std::chrono::seconds(5));
  // cncd-telemetry itself is not stuck either.
  EXPECT_EQ(get("/metrics").status, 200);
  ::close(silent);
}

}  // namespace
}  // namespace cncd::test
