// [WEB]: cncd-web's keys, their defaults and what is refused.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

namespace fs = std::filesystem;

class WebConfigTest : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fake_env() = {{"HOME", (dir_ / "home").string()}, {"XDG_STATE_HOME", (dir_ / "st").string()}};
    fs::create_directories(dir_ / "conf/nc");
    fs::create_directories(dir_ / "shared");
  }

  // The machine with `display` in [DISPLAY] and `web` in [WEB]; the [WEB] header is line 43.
  LoadResult load(const std::string& web, const std::string& display = "") {
    LoadOptions options;
    options.getenv = fake_getenv;
    return load_machine_config(
        write("conf/mill.ini", minimal_ini() + "[WEB]\n" + web + "[DISPLAY]\n" + display), options);
  }
  // "FILE:LINE: [WEB] KEY: message" for line `line` of the [WEB] section (1 = its first key).
  std::string problem(int line, const std::string& key, const std::string& message) const {
    return at("conf/mill.ini", 42 + line) + ": [WEB] " + key + ": " + message;
  }
};

TEST_F(WebConfigTest, DefaultsFollowTheContract) {
  const auto result = load("");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const WebConfig& web = result.config->web;
  EXPECT_EQ(web.listen, "127.0.0.1");
  EXPECT_EQ(web.port, 8080);
  EXPECT_EQ(web.program_dir, dir_ / "conf");  // the first (here the only) program directory
  EXPECT_EQ(web.max_upload_bytes, 64LL << 20);
  EXPECT_EQ(web.users_file, dir_ / "st/cncd/mill/web-users");
  EXPECT_TRUE(web.tls_cert.empty());
  EXPECT_TRUE(web.tls_key.empty());
  EXPECT_TRUE(web.allowed_origins.empty());
  EXPECT_EQ(web.session_hours, 12);
  EXPECT_EQ(web.max_clients, 64);
  EXPECT_DOUBLE_EQ(web.jog_heartbeat_s, 0.25);
}

TEST_F(WebConfigTest, EveryKeyIsRead) {
  const auto result = load(
      "LISTEN = 0.0.0.0\nPORT = 8443\nPROGRAM_DIR = ../shared/\nMAX_UPLOAD_MB = 3\n"
      "USERS_FILE = web/users\nTLS_CERT = tls/cert.pem\nTLS_KEY = /etc/cncd/key.pem\n"
      "ALLOWED_ORIGINS = https://cnc.example, http://pendant:8080  https://[::1]:8443\n"
      "SESSION_HOURS = 2\nMAX_CLIENTS = 5\nJOG_HEARTBEAT = 0.1\n",
      "PROGRAM_PREFIX = nc\n[CNCD]\nPROGRAM_DIRS = ../shared\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const WebConfig& web = result.config->web;
  EXPECT_EQ(web.listen, "0.0.0.0");
  EXPECT_EQ(web.port, 8443);
  EXPECT_EQ(web.program_dir, dir_ / "shared");
  EXPECT_EQ(web.max_upload_bytes, 3LL << 20);
  EXPECT_EQ(web.users_file, dir_ / "st/cncd/mill/web/users");  // relative: the state directory
  EXPECT_EQ(web.tls_cert, dir_ / "conf/tls/cert.pem");         // relative: beside the INI
  EXPECT_EQ(web.tls_key, "/etc/cncd/key.pem");
  EXPECT_EQ(web.allowed_origins,
            (std::vector<std::string>{"https://cnc.example", "http://pendant:8080",
                                      "https://[::1]:8443"}));
  EXPECT_EQ(web.session_hours, 2);
  EXPECT_EQ(web.max_clients, 5);
  EXPECT_DOUBLE_EQ(web.jog_heartbeat_s, 0.1);
}

TEST_F(WebConfigTest, ProgramDirDefaultsToTheFirstProgramDirectory) {
  const auto result = load("", "PROGRAM_PREFIX = nc\n[CNCD]\nPROGRAM_DIRS = ../shared\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->web.program_dir, dir_ / "conf/nc");
}

TEST_F(WebConfigTest, ProgramDirMustBeOneOfCncdsProgramDirectories) {
  // Below a program directory is not one: the contract is one of them, as listed.
  for (const std::string dir : {"/tmp", "../shared", "nc/sub"}) {
    const auto result = load("PROGRAM_DIR = " + dir + "\n", "PROGRAM_PREFIX = nc\n");
    const std::string resolved = (dir_ / "conf" / dir).lexically_normal().string();
    const std::string shown = dir == "/tmp" ? "/tmp" : resolved;
    EXPECT_EQ(strings(result.problems),
              std::vector<std::string>{problem(
                  1, "PROGRAM_DIR",
                  "'" + shown +
                      "' is not one of cncd's program directories ([DISPLAY] PROGRAM_PREFIX, "
                      "[CNCD] PROGRAM_DIRS): " +
                      (dir_ / "conf/nc").string())})
        << dir;
  }
}

TEST_F(WebConfigTest, TlsNeedsBothCertificateAndKey) {
  EXPECT_EQ(strings(load("TLS_CERT = c.pem\n").problems),
            std::vector<std::string>{problem(
                1, "TLS_CERT", "TLS_KEY is missing: TLS needs both the certificate and its key")});
  EXPECT_EQ(strings(load("PORT = 1\nTLS_KEY = k.pem\n").problems),
            std::vector<std::string>{problem(
                2, "TLS_KEY", "TLS_CERT is missing: TLS needs both the certificate and its key")});
}

TEST_F(WebConfigTest, ListenMustBeAnIpAddress) {
  EXPECT_EQ(strings(load("LISTEN =\n").problems),
            std::vector<std::string>{
                problem(1, "LISTEN", "empty; give an address such as 127.0.0.1, 0.0.0.0 or ::")});
  EXPECT_EQ(
      strings(load("LISTEN = localhost\n").problems),
      std::vector<std::string>{problem(1, "LISTEN",
                                       "'localhost' is not an IP address (e.g. 127.0.0.1, 0.0.0.0, "
                                       "::1 or ::)")});
  const auto v6 = load("LISTEN = [::1]\n");
  ASSERT_TRUE(v6.ok()) << ::testing::PrintToString(strings(v6.problems));
  EXPECT_EQ(v6.config->web.listen, "::1");
}

TEST_F(WebConfigTest, NumbersOutOfRangeAreRefused) {
  for (const std::string key :
       {"PORT = 0", "PORT = 65536", "MAX_UPLOAD_MB = 0", "SESSION_HOURS = 0", "MAX_CLIENTS = 0",
        "JOG_HEARTBEAT = 0.01", "JOG_HEARTBEAT = 6"}) {
    const auto result = load(key + "\n");
    EXPECT_FALSE(result.ok()) << key;
    ASSERT_EQ(result.problems.size(), 1u) << key;
    EXPECT_EQ(result.problems[0].line, 43) << key;
    EXPECT_EQ(result.problems[0].key, key.substr(0, key.find(' '))) << key;
  }
}

TEST_F(WebConfigTest, MalformedOriginsAreRefused) {
  const auto result =
      load("ALLOWED_ORIGINS = https://ok.example ftp://x https://a/ http://b:99999\n");
  EXPECT_EQ(strings(result.problems),
            (std::vector<std::string>{
                problem(1, "ALLOWED_ORIGINS", "'ftp://x' does not start with http:// or https://"),
                problem(1, "ALLOWED_ORIGINS",
                        "'https://a/' has more than scheme://host[:port] (a browser sends no "
                        "path, not even '/')"),
                problem(1, "ALLOWED_ORIGINS", "'http://b:99999' has a port that is not 1..65535"),
            }));
}

TEST_F(WebConfigTest, UnknownKeysAreProblems) {
  EXPECT_EQ(strings(load("LISTN = 0.0.0.0\n").problems),
            std::vector<std::string>{
                problem(1, "LISTN", "unknown key in cncd-web's section; did you mean LISTEN?")});
}

TEST_F(WebConfigTest, AbsoluteUsersFileStaysWhereItIs) {
  const auto result = load("USERS_FILE = /etc/cncd/web-users\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->web.users_file, "/etc/cncd/web-users");
}

}  // namespace
}  // namespace cncd::config::test
