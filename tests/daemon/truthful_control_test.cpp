// Control methods answer success only when the machine does what they ask: a drive that does
// not answer, an estop input still asserted, a home or run the machine cannot carry out is the
// answer's error (and cncctl's exit status), not a success followed by an event.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// `ini` with each `from` replaced by its `to` (each must be there).
void rewrite(const fs::path& ini, const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = slurp(ini);
  for (const auto& [from, to] : edits) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  std::ofstream(ini) << text;
}

// A loopback TCP port nobody listens on.
int closed_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  bind(fd, reinterpret_cast<sockaddr*>(&address), size);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  close(fd);
  return ntohs(address.sin_port);
}

class ControlTruthTest : public ::testing::Test {
 protected:
  std::string start(const fs::path& ini) {
    const std::string error = daemon_.start(dir_.path(), {"--ini", ini.string()});
    if (!error.empty()) return error;
    return client_.connect(daemon_.socket());
  }
  json call(const std::string& method, const json& params = nullptr) {
    return client_.call(method, params, 30000);
  }
  json status() { return result_of(call("status.get")); }
  CommandResult cncctl(const std::vector<std::string>& args) {
    return run_cncctl(daemon_.socket(), args);
  }

  TempDir dir_;
  DaemonProcess daemon_;
  daemon::Client client_;
};

// The Modbus machine with its drives on a port where nothing answers.
TEST_F(ControlTruthTest, MachineOnWithAnUnreachableDriveIsAnErrorNamingJointDriveAndReason) {
  const fs::path ini = copy_example_machine(dir_.path(), "modbus_sim");
  rewrite(ini, {{"PORT = 1502", "PORT = " + std::to_string(closed_port())}});
  ASSERT_EQ(start(ini), "");
  result_of(call("machine.reset"));
  const json r = call("machine.on");
  EXPECT_EQ(error_code(r), 1008) << r.dump();
  const std::string message = r["error"].value("message", "");
  EXPECT_NE(message.find("did not come on"), std::string::npos) << message;
  EXPECT_NE(message.find("joint 0"), std::string::npos) << message;
  EXPECT_NE(message.find("MODBUS_0 slave 1"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot connect"), std::string::npos) << message;
  EXPECT_EQ(status()["state"], "off");

  // Inside a batch the answer waits for the drives too.
  client_.send_raw(
      R"([{"jsonrpc":"2.0","id":"b1","method":"machine.on"},)"
      R"({"jsonrpc":"2.0","id":"b2","method":"status.get","params":{"fields":["state"]}}])"
      "\n");
  json batch;
  while (!batch.is_array())
    batch = json::parse(client_.read_line(30000));  // events come too
  ASSERT_TRUE(batch.is_array()) << batch.dump();
  ASSERT_EQ(batch.size(), 2u) << batch.dump();
  EXPECT_EQ(batch[0]["error"]["code"], 1008) << batch.dump();
  EXPECT_EQ(batch[1]["result"]["state"], "off") << batch.dump();

  const CommandResult on = cncctl({"on"});
  EXPECT_EQ(on.exit_status, 1) << on.err;
  EXPECT_NE(on.err.find("MODBUS_0 slave 1"), std::string::npos) << on.err;
  EXPECT_NE(on.err.find("cannot connect"), std::string::npos) << on.err;
}

// A [GPIO] ESTOP_LINE that reads asserted (the recording chip's inputs are low, and the line
// is active low): reset cannot leave estop.
TEST_F(ControlTruthTest, ResetWithTheEstopInputAssertedIsAnError) {
  const fs::path ini = copy_example_machine(dir_.path(), "gpio_vcd_mill");
  rewrite(ini,
          {{"CHIP = vcd:/tmp/cncd-steps.vcd", "CHIP = vcd:" + (dir_.path() / "steps.vcd").string() +
                                                  "\nESTOP_LINE = GPIO20\nESTOP_ACTIVE_LOW = 1"}});
  ASSERT_EQ(start(ini), "");
  const json r = call("machine.reset");
  EXPECT_EQ(error_code(r), 1008) << r.dump();
  EXPECT_NE(r.dump().find("estop input asserted"), std::string::npos) << r.dump();
  EXPECT_EQ(status()["state"], "estop");
  const CommandResult reset = cncctl({"reset"});
  EXPECT_EQ(reset.exit_status, 1) << reset.err;
  EXPECT_NE(reset.err.find("estop input"), std::string::npos) << reset.err;
}

class MachineTruthTest : public MachineTest {};

TEST_F(MachineTruthTest, HomeWhileJoggingOrHomingIsRefused) {
  result_of(call("machine.reset"));
  result_of(call("machine.on"));
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 5}}));
  json r = call("machine.home");
  EXPECT_EQ(error_code(r), 1004) << r.dump();
  EXPECT_EQ(status()["motion"], "jogging");
  result_of(call("jog.stop", {{"axis", "X"}}));
  wait_until([](const json& s) { return s["motion"] == "idle"; });
  result_of(call("machine.home"));
  wait_until([](const json& s) {
    for (const auto& h : s["homed"])
      if (!h.get<bool>()) return false;
    return s["motion"] == "idle";
  });
}

TEST_F(MachineTruthTest, MachineOnAnswersOnceTheMachineIsOn) {
  result_of(call("machine.reset"));
  result_of(call("machine.on"));
  const json s = status();
  EXPECT_EQ(s["state"], "on");
  EXPECT_EQ(s["fault"], "");
  // Already on: answered at once.
  result_of(call("machine.on"));
}

// The program was checked where the machine stood when it was opened; moved since, its first
// move leaves the soft limits, and the run ends before it starts.
TEST_F(MachineTruthTest, RunThatEndsBeforeItMovesIsAnError) {
  ready_machine();
  const fs::path program = dir_.write("relative.ngc", "G91 G0 X50\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  mdi("G53 G0 X280");
  const json r = call("program.run");
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_NE(r.dump().find("relative.ngc:1"), std::string::npos) << r.dump();
  const json s = status();
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["program"]["result"], "error");
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 280.0, 1e-9);
}

}  // namespace
}  // namespace cncd::test
