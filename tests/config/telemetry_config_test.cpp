// [TELEMETRY]: the job history's part count and cncd-telemetry's keys, their defaults and what
// is refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

class TelemetryConfigTest : public TempDirTest {
 protected:
  LoadResult load(const std::string& telemetry, const std::string& machine = "MACHINE = test\n") {
    LoadOptions options;
    options.getenv = fake_getenv;
    std::string ini = minimal_ini();
    ini.replace(ini.find("MACHINE = test\n"), 15, machine);
    return load_machine_config(write("mill.ini", ini + "[TELEMETRY]\n" + telemetry), options);
  }
  // The one problem of `telemetry`, without its place.
  std::string problem(const std::string& telemetry) {
    const auto result = load(telemetry);
    if (result.problems.size() != 1) return ::testing::PrintToString(strings(result.problems));
    const std::string text = strings(result.problems)[0];
    return text.substr(text.find("[TELEMETRY]"));
  }
};

TEST_F(TelemetryConfigTest, DefaultsFollowTheContract) {
  const auto result = load("");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const TelemetryConfig& t = result.config->telemetry;
  EXPECT_EQ(t.part_count, TelemetryConfig::PartCount::m30);
  EXPECT_EQ(t.machine_id, "test");
  EXPECT_EQ(t.metrics_address, "127.0.0.1");
  EXPECT_EQ(t.metrics_port, 9877);
  EXPECT_EQ(t.shdr_address, "127.0.0.1");
  EXPECT_EQ(t.shdr_port, 7878);
  EXPECT_EQ(t.mqtt_host, "");
  EXPECT_EQ(t.mqtt_port, 1883);
  EXPECT_EQ(t.mqtt_protocol, 5);
  EXPECT_EQ(t.topic_prefix, "cncd/test");
  EXPECT_DOUBLE_EQ(t.position_hz, 5);
  EXPECT_EQ(t.event_queue, 10000);
}

TEST_F(TelemetryConfigTest, MqttKeysAreRead) {
  const auto result = load(
      "MQTT_HOST = broker.shop\nMQTT_PORT = 8883\nMQTT_USERNAME = mill\nMQTT_PASSWORD = s3 cret\n"
      "MQTT_TLS_CA = ca.pem\nMQTT_PROTOCOL = 3.1.1\nTOPIC_PREFIX = shop/bay2/mill-1\n"
      "POSITION_HZ = 0\nEVENT_QUEUE = 50\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const TelemetryConfig& t = result.config->telemetry;
  EXPECT_EQ(t.mqtt_host, "broker.shop");
  EXPECT_EQ(t.mqtt_port, 8883);
  EXPECT_EQ(t.mqtt_username, "mill");
  EXPECT_EQ(t.mqtt_password, "s3 cret");
  EXPECT_EQ(t.mqtt_tls_ca, dir_ / "ca.pem");
  EXPECT_EQ(t.mqtt_protocol, 311);
  EXPECT_EQ(t.topic_prefix, "shop/bay2/mill-1");
  EXPECT_DOUBLE_EQ(t.position_hz, 0);
  EXPECT_EQ(t.event_queue, 50);
  for (const std::string bad : {"shop/+/mill", "shop/#", "/shop", "shop/"}) {
    EXPECT_EQ(problem("TOPIC_PREFIX = " + bad + "\n"),
              "[TELEMETRY] TOPIC_PREFIX: '" + bad +
                  "' is not a topic prefix: no '+' or '#', no '/' at either end (e.g. "
                  "shop/bay2/mill-1)")
        << bad;
  }
}

TEST_F(TelemetryConfigTest, EveryKeyIsRead) {
  const auto result = load(
      "PART_COUNT = m2\nMACHINE_ID = mill-2.bay_3\nMETRICS_LISTEN = [::1]:9100\n"
      "SHDR_LISTEN = 0.0.0.0\nSHDR_PORT = 0\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const TelemetryConfig& t = result.config->telemetry;
  EXPECT_EQ(t.part_count, TelemetryConfig::PartCount::m2);
  EXPECT_EQ(t.machine_id, "mill-2.bay_3");
  EXPECT_EQ(t.metrics_address, "::1");
  EXPECT_EQ(t.metrics_port, 9100);
  EXPECT_EQ(t.shdr_address, "0.0.0.0");
  EXPECT_EQ(t.shdr_port, 0);
  EXPECT_EQ(load("METRICS_LISTEN = off\n").config->telemetry.metrics_port, 0);
  EXPECT_EQ(load("PART_COUNT = off\n").config->telemetry.part_count,
            TelemetryConfig::PartCount::off);
}

TEST_F(TelemetryConfigTest, TheMachineIdComesFromTheMachineNameMadeSafe) {
  EXPECT_EQ(load("", "MACHINE = Haas VF-2 #3\n").config->telemetry.machine_id, "Haas_VF-2__3");
  // No name: the INI's.
  EXPECT_EQ(load("", "").config->telemetry.machine_id, "mill");
}

TEST_F(TelemetryConfigTest, BadValuesAreRefusedNamingTheKey) {
  EXPECT_EQ(problem("MACHINE_ID = cnc/1\n"),
            "[TELEMETRY] MACHINE_ID: 'cnc/1' may hold only letters, digits, '-', '_' and '.' (it "
            "is part of MQTT topics and metric labels)");
  for (const std::string bad : {"9877", "localhost:9877", "127.0.0.1:", "127.0.0.1:0",
                                "127.0.0.1:65536", "127.0.0.1:98x"}) {
    EXPECT_EQ(problem("METRICS_LISTEN = " + bad + "\n"),
              "[TELEMETRY] METRICS_LISTEN: '" + bad +
                  "' is not ADDRESS:PORT (e.g. 127.0.0.1:9877, [::1]:9877, 0.0.0.0:9877) or off")
        << bad;
  }
  EXPECT_EQ(problem("SHDR_LISTEN = example.com\n"),
            "[TELEMETRY] SHDR_LISTEN: 'example.com' is not an IP address (e.g. 127.0.0.1, "
            "0.0.0.0 or ::)");
  EXPECT_NE(problem("SHDR_PORT = 70000\n").find("[TELEMETRY] SHDR_PORT"), std::string::npos);
  EXPECT_NE(problem("PART_COUNT = m3\n").find("[TELEMETRY] PART_COUNT"), std::string::npos);
  EXPECT_EQ(problem("TOPIC_PREFX = x\n"),
            "[TELEMETRY] TOPIC_PREFX: unknown key in cncd's telemetry section; did you mean "
            "TOPIC_PREFIX?");
}

// The fleet page links each machine's own dashboard: given, off, or cncd-web's from [WEB].
TEST_F(TelemetryConfigTest, DashboardUrlIsGivenOrCncdWebs) {
  const auto url = [&](const std::string& text) {
    const auto result = load(text);
    EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
    return result.ok() ? result.config->telemetry.dashboard_url : std::string("?");
  };
  EXPECT_EQ(url(""), "");
  EXPECT_EQ(url("DASHBOARD_URL = https://mill-1.shop/cnc/\n"), "https://mill-1.shop/cnc/");
  EXPECT_EQ(url("[WEB]\nLISTEN = 127.0.0.1\nPORT = 8081\n"), "http://127.0.0.1:8081/");
  EXPECT_EQ(url("[WEB]\nLISTEN = ::1\n"), "http://[::1]:8080/");
  EXPECT_EQ(url("DASHBOARD_URL = off\n[WEB]\nLISTEN = 127.0.0.1\n"), "");
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(url("[WEB]\nLISTEN = 0.0.0.0\nPORT = 80\n"), "http://" + std::string(host) + ":80/");
  for (const std::string bad : {"javascript:alert(1)", "http://a b/", "ftp://x/", "http://x/\"<"}) {
    EXPECT_EQ(problem("DASHBOARD_URL = " + bad + "\n"),
              "[TELEMETRY] DASHBOARD_URL: '" + bad +
                  "' is not an http:// or https:// URL without blanks, quotes or <> (e.g. "
                  "http://mill-1.shop:8080/), nor off")
        << bad;
  }
}

}  // namespace
}  // namespace cncd::config::test
