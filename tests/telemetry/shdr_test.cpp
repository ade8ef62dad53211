// The MTConnect SHDR adapter of the real cncd-telemetry, read as an agent reads it.
#include <map>

#include "telemetry_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// An SHDR connection: lines as they come, and the latest value of each data item.
class ShdrClient {
 public:
  explicit ShdrClient(int port) : fd_(connect_loopback(port, 1)) {}
  ~ShdrClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  // Whether the adapter closes the connection (within a second of silence at the most).
  bool closed() { return closed_by_peer(fd_); }
  void send(const std::string& text) { ::send(fd_, text.data(), text.size(), MSG_NOSIGNAL); }
  // The next whole line, or "" after a second without one.
  std::string line() {
    for (;;) {
      if (const auto end = buffer_.find('\n'); end != std::string::npos) {
        std::string out = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        take(out);
        return out;
      }
      char chunk[4096];
      const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
      if (n <= 0) return "";
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  // Reads lines until item `key` is `value` (within `seconds`).
  bool until(const std::string& key, const std::string& value, int seconds = 60) {
    for (int i = 0; i < seconds; ++i) {
      while (!line().empty()) {
        if (items[key] == value) return true;
      }
      if (items[key] == value) return true;
    }
    return false;
  }
  std::map<std::string, std::string> items;
  std::vector<std::string> pongs;

 private:
  // "time|key|value|key|value..." or "* PONG n".
  void take(const std::string& text) {
    if (text.rfind("* PONG", 0) == 0) {
      pongs.push_back(text);
      return;
    }
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (std::size_t bar; (bar = text.find('|', start)) != std::string::npos; start = bar + 1)
      fields.push_back(text.substr(start, bar - start));
    fields.push_back(text.substr(start));
    if (fields.size() >= 6 && fields[1] == "system") {
      items["system"] = fields[2];
      return;
    }
    for (std::size_t i = 1; i + 1 < fields.size(); i += 2)
      items[fields[i]] = fields[i + 1];
  }

  int fd_;
  std::string buffer_;
};

TEST_F(TelemetryTest, AnAgentGetsPongAndSeesARunAndItsPart) {
  ShdrClient agent(shdr_port_);
  ASSERT_TRUE(agent.ok());
  ASSERT_TRUE(agent.until("avail", "AVAILABLE"));
  EXPECT_TRUE(agent.until("estop", "TRIGGERED"));
  agent.send("* PING\n");
  for (int i = 0; i < 20 && agent.pongs.empty(); ++i)
    agent.line();
  ASSERT_EQ(agent.pongs.size(), 1u);
  EXPECT_EQ(agent.pongs[0], "* PONG 10000");
  ready_machine();
  ASSERT_TRUE(agent.until("execution", "READY"));
  ASSERT_TRUE(agent.until("partcount", "0"));
  EXPECT_EQ(agent.items["estop"], "ARMED");
  EXPECT_EQ(agent.items["system"], "NORMAL");
  start_program("part.ngc", "G21 G90 F600\nG1 X20 Y10\nG1 X0\nM30\n");
  EXPECT_TRUE(agent.until("execution", "ACTIVE"));
  EXPECT_EQ(agent.items["mode"], "AUTOMATIC");
  EXPECT_NE(agent.items["program"].find("part.ngc"), std::string::npos);
  EXPECT_TRUE(agent.until("execution", "READY"));
  EXPECT_TRUE(agent.until("partcount", "1"));
  EXPECT_EQ(agent.items["Xpos"], "0");
  EXPECT_EQ(agent.items["Ypos"], "10");
}

TEST_F(TelemetryTest, AgentsBeyondTheLimitAndLongLinesAreDropped) {
  std::vector<std::unique_ptr<ShdrClient>> agents;
  for (int i = 0; i < 8; ++i) {
    agents.push_back(std::make_unique<ShdrClient>(shdr_port_));
    ASSERT_TRUE(agents.back()->until("avail", "AVAILABLE"));
  }
  ShdrClient ninth(shdr_port_);
  EXPECT_EQ(ninth.line(), "") << "the ninth is closed at once";
  // A line over 1 KiB ends that agent's connection; the others are served on.
  agents[0]->send(std::string(5000, 'x') + "\n");
  EXPECT_TRUE(agents[0]->closed()) << "a line over 1 KiB leaves the connection open";
  agents[1]->send("* PING\n");
  EXPECT_TRUE(agents[1]->until("avail", "AVAILABLE", 1));
  for (int i = 0; i < 20 && agents[1]->pongs.empty(); ++i)
    agents[1]->line();
  EXPECT_EQ(agents[1]->pongs.size(), 1u);
}

TEST_F(TelemetryTest, DevicesXmlNamesEveryItem) {
  const auto r = run_command({CNCD_TELEMETRY_BINARY, "--ini", ini_.string(), "--devices-xml"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* id :
       {"avail", "estop", "system", "execution", "mode", "program", "line", "partcount", "tool",
        "path_feedrate", "path_feedrate_override", "Xpos", "Ypos", "Zpos", "Sspeed", "Sovr"}) {
    EXPECT_NE(r.out.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  }
  // Well-formed for an XML parser.
  const auto file = dir_.write("Devices.xml", r.out);
  const auto parsed =
      run_command({CNCD_PYTHON3, "-c", "import sys, xml.dom.minidom as m; m.parse(sys.argv[1])",
                   file.string()});
  EXPECT_EQ(parsed.exit_status, 0) << parsed.err;
}

}  // namespace
}  // namespace cncd::test
