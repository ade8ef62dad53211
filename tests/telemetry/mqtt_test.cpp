// MQTT from the real cncd-telemetry through a real mosquitto broker to a real subscriber.
#include <cstdio>
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
  void configure_mqtt(int port, const std::string& more = "") {
    std::ofstream(ini_, std::ios::trunc)
        << base_ini_ << "\n[TELEMETRY]\nMACHINE_ID = mill-1\nMQTT_HOST = 127.0.0.1\n"
        << "MQTT_PORT = " << port << "\nDASHBOARD_URL = http://mill-1.shop:8080/\n"
        << more;
  }
  // cncd-telemetry started again on the INI as it is now.
  void restart_telemetry() {
    telemetry_.reset();
    port_ = shdr_port_ = 0;
    start_telemetry();
  }
  // The broker started again with `settings` for its listener.
  void restart_broker(const std::string& settings) {
    broker_.stop();
    // mosquitto started as root reads its files as the user mosquitto.
    namespace fs = std::filesystem;
    fs::permissions(broker_dir_.path(), fs::perms::owner_all | fs::perms::group_read |
                                            fs::perms::group_exec | fs::perms::others_read |
                                            fs::perms::others_exec);
    for (const auto& entry : fs::directory_iterator(broker_dir_.path()))
      fs::permissions(entry.path(), fs::perms::others_read, fs::perm_options::add);
    broker_.settings(settings);
    ASSERT_EQ(broker_.start(), "");
  }
  // A certificate authority and a certificate it signs for 127.0.0.1, in the broker's folder
  // with `name` as their prefix; "" or why not.
  std::string make_certificates(const std::string& name) {
    const auto at = [&](const char* suffix) {
      return (broker_dir_.path() / (name + suffix)).string();
    };
    std::ofstream(at("-ext.cnf")) << "subjectAltName = IP:127.0.0.1\n";
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj",
              "/CN=" + name + " CA", "-keyout", at("-ca.key"), "-out", at("-ca.crt")},
             {"req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=127.0.0.1", "-keyout",
              at("-server.key"), "-out", at("-server.csr")},
             {"x509", "-req", "-days", "2", "-in", at("-server.csr"), "-CA", at("-ca.crt"),
              "-CAkey", at("-ca.key"), "-CAcreateserial", "-extfile", at("-ext.cnf"), "-out",
              at("-server.crt")}}) {
      std::vector<std::string> argv{"/usr/bin/openssl"};
      argv.insert(argv.end(), args.begin(), args.end());
      const auto r = run_command(argv);
      if (r.exit_status != 0) return "openssl " + args[0] + ": " + r.err;
    }
    return "";
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
  // Validates the payloads against docs/telemetry-schemas.json (python3-jsonschema); the
  // count of payloads by topic, empty on a failure (which fails the test).
  json schema_check(const std::vector<Message>& messages) {
    static constexpr const char* kCheck = R"(
import json, sys
from jsonschema import Draft202012Validator
schemas = json.load(open(sys.argv[1]))
Draft202012Validator.check_schema(schemas)
seen = {}
for line in open(sys.argv[2]):
    m = json.loads(line)
    topic = m["topic"].rsplit("/", 1)[1]
    if topic == "availability":
        continue
    name = {"events": "event"}.get(topic, topic)
    v = Draft202012Validator({"$ref": "#/$defs/" + name, "$defs": schemas["$defs"]})
    for e in v.iter_errors(json.loads(m["payload"])):
        sys.exit(f"{topic}: {e.message} at {list(e.absolute_path)} in {m['payload'][:400]}")
    seen[topic] = seen.get(topic, 0) + 1
print(json.dumps(seen))
)";
    std::string lines;
    for (const auto& m : messages)
      lines += json{{"topic", m.topic}, {"payload", m.payload}}.dump() + "\n";
    const auto file = broker_dir_.write("payloads.jsonl", lines);
    const auto r =
        run_command({CNCD_PYTHON3, "-c", kCheck,
                     std::string(CNCD_SOURCE_DIR) + "/docs/telemetry-schemas.json", file.string()});
    EXPECT_EQ(r.exit_status, 0) << r.err;
    return r.exit_status == 0 ? json::parse(r.out, nullptr, false) : json::object();
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
  // The fleet page's part count and link come with the state.
  EXPECT_TRUE(sub.got("/state", "\"parts\":1"));
  EXPECT_TRUE(sub.got("/state", "\"dashboard\":\"http://mill-1.shop:8080/\""));
  // cncd away: the state says so.
  daemon_.stop();
  ASSERT_TRUE(sub.got("/state", "\"cncd\":\"unreachable\""));
  // Every payload as docs/telemetry-schemas.json describes it.
  const json seen = schema_check(sub.messages());
  for (const char* topic : {"state", "position", "events", "job"})
    EXPECT_GE(seen.value(topic, 0), 1) << topic << " not seen: " << seen.dump();
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

TEST_F(MqttTest, APasswordBrokerTakesTheRightLoginAndNoSecretIsLogged) {
  const auto passwords = broker_dir_.path() / "passwords";
  ASSERT_EQ(run_command({"/usr/bin/mosquitto_passwd", "-b", "-c", passwords.string(), "mill",
                         "Open-sesame-42"})
                .exit_status,
            0);
  restart_broker("allow_anonymous false\npassword_file " + passwords.string() + "\n");
  const std::string port = std::to_string(broker_.port());
  configure_mqtt(broker_.port(), "MQTT_USERNAME = mill\nMQTT_PASSWORD = Open-sesame-42\n");
  restart_telemetry();
  Subscriber sub(broker_.port(), "cncd/mill-1/#", {"mill", "Open-sesame-42", ""});
  ASSERT_TRUE(sub.got("/availability", "online"));
  ASSERT_TRUE(sub.got("/state", "\"machine\":\"mill-1\""));
  metrics_with("cncd_telemetry_mqtt_connected{machine=\"mill-1\"} 1");
  std::string log = telemetry_->err_so_far();
  // A wrong password is refused, said so, and tried again later; nothing goes out.
  configure_mqtt(broker_.port(), "MQTT_USERNAME = mill\nMQTT_PASSWORD = Wrong-guess-17\n");
  restart_telemetry();
  for (int i = 0; i < 3000 && telemetry_->err_so_far().find("refused") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  log += telemetry_->err_so_far();
  EXPECT_NE(log.find("the broker refused the connection"), std::string::npos) << log;
  metrics_with("cncd_telemetry_mqtt_connected{machine=\"mill-1\"} 0");
  for (const std::string& secret : {std::string("Open-sesame"), std::string("Wrong-guess"), port})
    EXPECT_EQ(log.find(secret), std::string::npos) << secret << " is in the log:\n" << log;
}

TEST_F(MqttTest, TlsToABrokerOfTheShopsCaAndNotToAnother) {
  ASSERT_EQ(make_certificates("shop"), "");
  ASSERT_EQ(make_certificates("other"), "");
  const auto file = [&](const char* name) { return (broker_dir_.path() / name).string(); };
  restart_broker("allow_anonymous true\ncafile " + file("shop-ca.crt") + "\ncertfile " +
                 file("shop-server.crt") + "\nkeyfile " + file("shop-server.key") + "\n");
  configure_mqtt(broker_.port(), "MQTT_TLS_CA = " + file("shop-ca.crt") + "\n");
  restart_telemetry();
  Subscriber sub(broker_.port(), "cncd/mill-1/#", {"", "", file("shop-ca.crt")});
  ASSERT_TRUE(sub.got("/availability", "online"));
  ASSERT_TRUE(sub.got("/state", "\"machine\":\"mill-1\""));
  // A broker whose certificate the configured CA did not sign is not talked to.
  configure_mqtt(broker_.port(), "MQTT_TLS_CA = " + file("other-ca.crt") + "\n");
  restart_telemetry();
  metrics_with("cncd_telemetry_mqtt_connected{machine=\"mill-1\"} 0");
  for (int i = 0; i < 3000 && telemetry_->err_so_far().find("cannot reach") == std::string::npos;
       ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const std::string log = telemetry_->err_so_far();
  EXPECT_NE(log.find("MQTT: cannot reach the broker"), std::string::npos) << log;
  EXPECT_EQ(log.find(std::to_string(broker_.port())), std::string::npos) << log;
  // A CA file that is not there is a configuration error named at start.
  configure_mqtt(broker_.port(), "MQTT_TLS_CA = " + file("missing-ca.crt") + "\n");
  const auto r = run_command({CNCD_TELEMETRY_BINARY, "--ini", ini_.string(), "--socket",
                              daemon_.socket(), "--metrics-listen", "127.0.0.1:0"});
  EXPECT_NE(r.exit_status, 0);
  EXPECT_NE(r.err.find("missing-ca.crt"), std::string::npos) << r.err;
}

TEST_F(MqttTest, AFullQueueDropsTheOldestCountsThemAndKeepsTheNewest) {
  configure_mqtt(broker_.port(), "EVENT_QUEUE = 4\n");
  restart_telemetry();
  {
    Subscriber sub(broker_.port(), "cncd/mill-1/#");
    ASSERT_TRUE(sub.got("/availability", "online"));
  }
  ready_machine();
  const int port = broker_.port();
  broker_.stop();
  metrics_with("cncd_telemetry_mqtt_connected{machine=\"mill-1\"} 0");
  run_part();  // more events than the queue holds
  run_part();
  metrics_with("cncd_telemetry_mqtt_queued_messages{machine=\"mill-1\"} 4");
  const std::string dropped = metrics();
  EXPECT_EQ(dropped.find("cncd_telemetry_mqtt_dropped_total{machine=\"mill-1\"} 0\n"),
            std::string::npos)
      << dropped;
  EXPECT_NE(telemetry_->err_so_far().find("messages dropped unsent, the queue holding 4"),
            std::string::npos)
      << telemetry_->err_so_far();
  ASSERT_EQ(broker_.start(port), "");
  Subscriber sub(port, "cncd/mill-1/#");
  ASSERT_TRUE(sub.subscribed());
  ASSERT_TRUE(sub.got("/job", "\"result\":\"done\"", 90));
  metrics_with("cncd_telemetry_mqtt_queued_messages{machine=\"mill-1\"} 0");
  // The newest came, in order; the oldest are gone.
  const auto seqs = event_seqs(sub.messages());
  const json events = result_of(call("errors.list"))["events"];
  ASSERT_FALSE(seqs.empty());
  EXPECT_EQ(seqs.back(), events.back()["seq"].get<std::uint64_t>());
  EXPECT_LE(seqs.size(), 4u);
  expect_no_gap(seqs);
}

// A "broker" that takes the connection and never says a word: the machine is not held up. The
// stop's answer time and the servo overruns during a run are measured once with no telemetry
// and once with cncd-telemetry stuck on that broker.
TEST_F(MqttTest, ABrokerThatNeverAnswersHoldsNothingUp) {
  const int silent = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(silent, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(silent, 16), 0);
  socklen_t size = sizeof addr;
  ::getsockname(silent, reinterpret_cast<sockaddr*>(&addr), &size);
  struct Figures {
    std::chrono::steady_clock::duration stop;
    std::uint64_t overruns;
  };
  const auto run_and_stop = [this] {
    ready_machine();
    const auto overruns = status()["rt"]["overruns"].get<std::uint64_t>();
    start_program("long.ngc", "G21 G90 F100\n(MSG, away)\nG1 X100\nM30\n");
    std::this_thread::sleep_for(std::chrono::seconds(2));
    const auto before = std::chrono::steady_clock::now();
    result_of(call("machine.estop"));
    const Figures f{std::chrono::steady_clock::now() - before,
                    status()["rt"]["overruns"].get<std::uint64_t>() - overruns};
    EXPECT_EQ(status()["state"], "estop");
    return f;
  };
  telemetry_.reset();
  port_ = shdr_port_ = 0;
  const Figures alone = run_and_stop();
  configure_mqtt(ntohs(addr.sin_port));
  start_telemetry();
  const Figures stuck = run_and_stop();
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  std::printf(
      "stop answered in %.1f ms alone, %.1f ms with the broker silent; overruns %llu, %llu\n",
      ms(alone.stop), ms(stuck.stop), static_cast<unsigned long long>(alone.overruns),
      static_cast<unsigned long long>(stuck.overruns));
  // A stop waits for nothing of the telemetry's: a few scheduler wake-ups at most.
  EXPECT_LT(stuck.stop, alone.stop + std::chrono::milliseconds(250));
  // This virtual machine's late wake-ups give a handful of overruns in 2 s either way.
  EXPECT_LE(stuck.overruns, alone.overruns + 25);
  // cncd-telemetry itself is not stuck either.
  EXPECT_EQ(get("/metrics").status, 200);
  ::close(silent);
}

}  // namespace
}  // namespace cncd::test
