// The real cncd process, started on a temporary socket with the simulated machine.
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "client.hpp"
#include "client_checks.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

const std::string kSimIni = std::string(CNCD_SOURCE_DIR) + "/config/examples/sim_mm.ini";
const std::string kSeedProgram = std::string(CNCD_SOURCE_DIR) + "/examples/g81_example1.ngc";

json result(const json& response) {
  EXPECT_TRUE(response.contains("result")) << response.dump();
  return response.value("result", json());
}

class DaemonTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto ini = copy_example_machine(dir_.path());
    const std::string error = daemon_.start(dir_.path(), {"--ini", ini.string()});
    ASSERT_EQ(error, "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }

  // Brings the machine out of estop, on and homed.
  void ready_machine() {
    result(client_.call("machine.reset"));
    result(client_.call("machine.on"));
    result(client_.call("machine.home"));
    wait_until([](const json& s) {
      for (const auto& h : s["homed"]) {
        if (!h.get<bool>()) return false;
      }
      return s["motion"] == "idle";
    });
  }

  template <typename Predicate>
  json wait_until(Predicate done, std::chrono::seconds limit = std::chrono::seconds(60)) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    json s;
    while (std::chrono::steady_clock::now() < deadline) {
      s = result(client_.call("status.get"));
      if (done(s)) return s;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "condition not reached; last status: " << s.dump();
    return s;
  }

  json run_to_end(const std::string& path) {
    result(client_.call("program.open", {{"path", path}}));
    result(client_.call("program.run"));
    return wait_until([](const json& s) { return s["exec"] == "idle"; });
  }

  TempDir dir_;
  DaemonProcess daemon_;
  daemon::Client client_;
};

TEST_F(DaemonTest, StartsInEstopUnhomed) {
  const json s = result(client_.call("status.get"));
  EXPECT_EQ(s["state"], "estop");
  EXPECT_EQ(s["exec"], "idle");
  ASSERT_EQ(s["homed"].size(), 3u);
  EXPECT_FALSE(s["homed"][0].get<bool>());
  EXPECT_TRUE(s["position"]["commanded"].contains("x"));
  EXPECT_TRUE(s["position"]["actual"].contains("z"));
  EXPECT_FALSE(s["position"]["commanded"].contains("a"));
}

TEST_F(DaemonTest, MachineOnIsRefusedInEstop) {
  const json r = client_.call("machine.on");
  ASSERT_TRUE(r.contains("error"));
  EXPECT_EQ(r["error"]["code"], 1001);
}

TEST_F(DaemonTest, RunIsRefusedBeforeHoming) {
  result(client_.call("machine.reset"));
  result(client_.call("machine.on"));
  result(client_.call("program.open", {{"path", kSeedProgram}}));
  const json r = client_.call("program.run");
  ASSERT_TRUE(r.contains("error")) << r.dump();
  EXPECT_EQ(r["error"]["code"], 1002);
}

TEST_F(DaemonTest, RunsTheSeedG81ExampleToItsEnd) {
  ready_machine();
  const json s = run_to_end(kSeedProgram);
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  const auto& pos = s["position"]["commanded"];
  EXPECT_NEAR(pos["x"].get<double>(), 4.0, 1e-9);
  EXPECT_NEAR(pos["y"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(pos["z"].get<double>(), 3.0, 1e-9);
  // G0 to the start, then the cycle: XY traverse, Z traverse to R, feed to Z, retract.
  EXPECT_EQ(s["program"]["moves"], 5);
  // Read in the period the program ended, the feedback may still be one period's step short.
  const auto& actual = s["position"]["actual"];
  EXPECT_NEAR(actual["x"].get<double>(), 4.0, 0.01);
  EXPECT_NEAR(actual["z"].get<double>(), 3.0, 0.01);
}

TEST_F(DaemonTest, ProgramErrorNamesFileAndLine) {
  ready_machine();
  const std::string bad = "G21 G90\nG0 X1\nG81 X2 Y2 Z1 R0.5\nM2\n";
  const auto program = dir_.write("bad.ngc", bad);
  // program.open runs the program through the interpreter and refuses it there.
  const json r = client_.call("program.open", {{"path", program.string()}});
  ASSERT_TRUE(r.contains("error")) << r.dump();
  EXPECT_EQ(r["error"]["code"], 1003);
  EXPECT_NE(r["error"].value("message", "").find("bad.ngc:3"), std::string::npos) << r.dump();
  // Changed on disk after it was opened, it stops the run at that line.
  dir_.write("bad.ngc", "G21 G90\nM2\n");
  result(client_.call("program.open", {{"path", program.string()}}));
  dir_.write("bad.ngc", bad);
  result(client_.call("program.run"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "error");
  const std::string error = s["program"]["error"];
  EXPECT_NE(error.find("bad.ngc:3"), std::string::npos) << error;
}

TEST_F(DaemonTest, OpenMissingProgramIsRefused) {
  const json r = client_.call("program.open", {{"path", (dir_.path() / "none.ngc").string()}});
  ASSERT_TRUE(r.contains("error"));
  EXPECT_EQ(r["error"]["code"], 1003);
}

TEST_F(DaemonTest, EstopDuringMotionStopsTheProgram) {
  ready_machine();
  const auto program = dir_.write("long.ngc", "G21 G90 G1 F600 X200\nM2\n");
  result(client_.call("program.open", {{"path", program.string()}}));
  result(client_.call("program.run"));
  wait_until([](const json& s) { return s["position"]["commanded"]["x"].get<double>() > 1.0; });
  result(client_.call("machine.estop"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["state"], "estop");
  EXPECT_EQ(s["program"]["result"], "aborted");
  expect_stopped_short_of_x200(client_, s, std::chrono::milliseconds(100));
}

TEST_F(DaemonTest, MdiAnswersOnceTheLineHasFinished) {
  ready_machine();
  const json r = client_.call("mdi.execute", {{"line", "G21 G90 G1 F1200 X10 Y-2"}}, 20000);
  ASSERT_TRUE(r.contains("result")) << r.dump();
  // Answered after the move: the machine is already there and at rest.
  const json s = result(client_.call("status.get"));
  EXPECT_EQ(s["position"]["commanded"]["x"], 10.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], -2.0);
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_EQ(s["exec"], "idle");
  // Modal state carries over from one MDI line to the next, as in LinuxCNC.
  ASSERT_TRUE(client_.call("mdi.execute", {{"line", "G91 X1"}}, 20000).contains("result"));
  EXPECT_EQ(result(client_.call("status.get"))["position"]["commanded"]["x"], 11.0);
}

TEST_F(DaemonTest, MdiErrorsComeBackAsErrors) {
  ready_machine();
  const json r = client_.call("mdi.execute", {{"line", "G1 X5"}});  // no feed rate yet
  ASSERT_TRUE(r.contains("error")) << r.dump();
  EXPECT_EQ(r["error"]["code"], 1003);
  const json batch = client_.call("mdi.execute", {{"line", "G0 X1\nG0 X2"}});
  EXPECT_EQ(batch["error"]["code"], -32602);
}

TEST_F(DaemonTest, AbortAnswersOnceTheMachineHasStopped) {
  ready_machine();
  const auto program = dir_.write("long.ngc", "G21 G90 G1 F3000 X250\nM2\n");
  result(client_.call("program.open", {{"path", program.string()}}));
  result(client_.call("program.run"));
  wait_until([](const json& s) { return s["velocity"].get<double>() > 40.0; });
  ASSERT_TRUE(client_.call("program.abort").contains("result"));
  const json s = result(client_.call("status.get"));
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_EQ(s["velocity"], 0.0);
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["program"]["result"], "aborted");
  EXPECT_LT(s["position"]["commanded"]["x"].get<double>(), 250.0);
}

TEST_F(DaemonTest, MalformedLineKeepsConnectionUsable) {
  client_.send_raw("{this is not json\n");
  const json error = json::parse(client_.read_line());
  EXPECT_EQ(error["error"]["code"], -32700);
  EXPECT_EQ(result(client_.call("status.get"))["state"], "estop");
}

TEST_F(DaemonTest, SigtermExitsCleanly) {
  EXPECT_EQ(daemon_.stop(), 0);
}

TEST_F(DaemonTest, CncctlRunsTheDemoSequence) {
  const std::vector<std::string> ctl{CNCCTL_BINARY, "--socket", daemon_.socket()};
  auto cncctl = [&](std::vector<std::string> args) {
    std::vector<std::string> argv = ctl;
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv);
  };
  EXPECT_EQ(cncctl({"reset"}).exit_status, 0);
  EXPECT_EQ(cncctl({"on"}).exit_status, 0);
  EXPECT_EQ(cncctl({"home"}).exit_status, 0);
  const auto run = cncctl({"run", kSeedProgram});
  EXPECT_EQ(run.exit_status, 0) << run.out << run.err;
  EXPECT_NE(run.out.find("done"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("X 4.0000  Y 5.0000  Z 3.0000"), std::string::npos) << run.out;
  const auto status = cncctl({"status", "--json"});
  EXPECT_EQ(status.exit_status, 0);
  EXPECT_EQ(json::parse(status.out)["state"], "on");
  EXPECT_EQ(cncctl({"mdi", "G0", "X1"}).exit_status, 0);
  EXPECT_EQ(json::parse(cncctl({"status", "--json"}).out)["position"]["commanded"]["x"], 1.0);
  EXPECT_EQ(cncctl({"mdi", "G1", "X"}).exit_status, 1);
  const auto errors = cncctl({"errors"});
  EXPECT_EQ(errors.exit_status, 0);
  EXPECT_NE(errors.out.find("g81_example1.ngc finished"), std::string::npos) << errors.out;
  // A refused request exits 2, a failed program 1.
  EXPECT_EQ(cncctl({"estop"}).exit_status, 0);
  EXPECT_EQ(cncctl({"on"}).exit_status, 2);
}

TEST(DaemonCommandLine, CheckConfigPrintsTheMachine) {
  const auto r = run_command({CNCD_BINARY, "--check-config", kSimIni});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("X"), std::string::npos);
}

TEST(DaemonCommandLine, InvalidConfigExits78WithLineNumbers) {
  TempDir dir;
  const auto ini = dir.write("bad.ini",
                             "[EMCMOT]\nSERVO_PERIOD = 1000000\n[TRAJ]\nCOORDINATES = X\n"
                             "LINEAR_UNITS = furlong\n[KINS]\nKINEMATICS = trivkins\nJOINTS = 1\n"
                             "[AXIS_X]\nMAX_VELOCITY = fast\n");
  for (const char* flag : {"--check-config", "--ini"}) {
    const auto r = run_command({CNCD_BINARY, flag, ini.string()});
    EXPECT_EQ(r.exit_status, 78) << flag;
    EXPECT_NE(r.err.find("bad.ini:5:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("bad.ini:10:"), std::string::npos) << r.err;
  }
}

TEST(DaemonCommandLine, UnknownArgumentIsAUsageError) {
  const auto r = run_command({CNCD_BINARY, "--frobnicate"});
  EXPECT_EQ(r.exit_status, 64);
}

}  // namespace
}  // namespace cncd::test
