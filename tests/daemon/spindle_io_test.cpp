// The spindle, user M codes and M66 on the real daemon and the simulated mill: feed moves wait
// for the spindle to reach speed, M5 and abort stop it, user M codes run between the moves
// around them and stop the program when they fail, M66 waits and puts its answer in #5399.
#include <sys/stat.h>

#include <fstream>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class SpindleIo : public MachineTest {
 protected:
  // Restarts cncd on the example mill with `keys` added to [CNCD] and `rs274` to [RS274NGC].
  void restart_with(const std::string& cncd_keys, const std::string& rs274_keys = "") {
    daemon_.stop();
    std::string text = slurp(ini_);
    text.insert(text.find("[CNCD]\n") + 7, cncd_keys);
    text.insert(text.find("[RS274NGC]\n") + 11, rs274_keys);
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  // An executable script in the test's directory "um".
  void script(const std::string& name, const std::string& body) {
    std::filesystem::create_directories(dir_.path() / "um");
    const auto path = dir_.write("um/" + name, "#!/bin/sh\n" + body);
    ::chmod(path.c_str(), 0755);
  }
  json run_to_end(const std::string& text) {
    start_program("prog.ngc", text);
    return wait_until([](const json& s) { return s["exec"] == "idle"; });
  }
};

TEST_F(SpindleIo, TheFeedStartsOnlyOnceTheSpindleIsAtSpeed) {
  ready_machine();
  start_program("spin.ngc", "G0 X0 Y0 Z5\nM3 S3000\nG1 Z-1 F600\nM2\n");
  bool waited = false;
  double rpm_when_feeding = -1;
  json s;
  for (int i = 0; i < 3000; ++i) {
    s = status();
    if (s["wait"].is_object() && s["wait"]["kind"] == "spindle_at_speed") {
      waited = true;
      EXPECT_LT(s["spindle"]["actual_rpm"].get<double>(), 2850.0);
      EXPECT_EQ(s["position"]["commanded"]["z"], 5.0);
    }
    if (rpm_when_feeding < 0 && s["position"]["commanded"]["z"].get<double>() < 5 - 1e-6 &&
        s["spindle"]["enabled"] == true)
      rpm_when_feeding = s["spindle"]["actual_rpm"].get<double>();
    if (s["exec"] == "idle") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_TRUE(waited) << "the spindle (6000 rpm/s) takes half a second to reach 3000 rpm";
  EXPECT_GE(rpm_when_feeding, 2850.0);
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["z"], -1.0);
  // M2 stops it.
  EXPECT_EQ(s["spindle"]["enabled"], false);
}

TEST_F(SpindleIo, M5AndAbortStopTheSpindle) {
  ready_machine();
  mdi("M3 S2000");
  json s = wait_until([](const json& st) { return st["spindle"]["at_speed"] == true; });
  EXPECT_EQ(s["spindle"]["enabled"], true);
  EXPECT_NEAR(s["spindle"]["actual_rpm"].get<double>(), 2000, 100);
  mdi("M5");
  s = status();
  EXPECT_EQ(s["spindle"]["enabled"], false);
  EXPECT_EQ(s["spindle"]["commanded_rpm"], 0.0);
  mdi("M4 S1000 M8");
  EXPECT_EQ(status()["spindle"]["direction"], -1);
  EXPECT_EQ(status()["coolant"]["flood"], true);
  result_of(call("program.abort"));
  s = status();
  EXPECT_EQ(s["spindle"]["enabled"], false);
  EXPECT_EQ(s["coolant"]["flood"], false);
}

TEST_F(SpindleIo, TheSpindleOverrideChangesTheSpeedLive) {
  ready_machine();
  mdi("M3 S1000");
  // [DISPLAY] MAX_SPINDLE_OVERRIDE of the example allows 120 %.
  result_of(call("override.spindle", {{"value", 1.2}}));
  EXPECT_EQ(status()["spindle"]["commanded_rpm"], 1200.0);
  mdi("M51 P0");
  EXPECT_EQ(status()["spindle"]["commanded_rpm"], 1000.0);
}

TEST_F(SpindleIo, AUserMCodeRunsWithPAndQBetweenTheMovesAroundIt) {
  ASSERT_NO_FATAL_FAILURE(restart_with("", "USER_M_PATH = um\n"));
  const auto out = dir_.path() / "m101.out";
  script("M101", "echo \"$1 $2\" > " + out.string() + "\nsleep 0.5\n");
  ready_machine();
  start_program("user.ngc", "G0 X1\nM101 P2 Q3.5\nG0 X2\nM2\n");
  const json waiting = wait_until(
      [](const json& s) { return s["wait"].is_object() && s["wait"]["kind"] == "user_m"; });
  EXPECT_EQ(waiting["position"]["commanded"]["x"], 1.0);
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 2.0);
  EXPECT_EQ(slurp(out), "2.000000 3.500000\n");
}

TEST_F(SpindleIo, AUserMCodeThatFailsStopsTheProgramNamingIt) {
  ASSERT_NO_FATAL_FAILURE(restart_with("", "USER_M_PATH = um\n"));
  script("M103", "exit 3\n");
  ready_machine();
  const json s = run_to_end("G0 X1\nM103\nG0 X2\nM2\n");
  EXPECT_EQ(s["program"]["result"], "error");
  const std::string error = s["program"]["error"];
  EXPECT_NE(error.find("prog.ngc:2: "), std::string::npos) << error;
  EXPECT_NE(error.find("um/M103 exited with status 3"), std::string::npos) << error;
  EXPECT_EQ(s["position"]["commanded"]["x"], 1.0);
}

TEST_F(SpindleIo, AUserMCodeThatHangsTimesOut) {
  ASSERT_NO_FATAL_FAILURE(restart_with("USER_M_TIMEOUT = 0.5\n", "USER_M_PATH = um\n"));
  script("M104", "sleep 30\n");
  ready_machine();
  const auto started = std::chrono::steady_clock::now();
  const json s = run_to_end("M104\nG0 X2\nM2\n");
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(10));
  EXPECT_EQ(s["program"]["result"], "error");
  const std::string error = s["program"]["error"];
  EXPECT_NE(error.find("M104 did not finish within 0.5 s"), std::string::npos) << error;
}

TEST_F(SpindleIo, M66WaitsForAnInputAndPutsItsAnswerIn5399) {
  // Output 1 is wired back to input 0 (one sim: signal); input 2 is never set.
  ASSERT_NO_FATAL_FAILURE(restart_with("DIGITAL_OUTPUT_1 = sim:door_closed\n"));
  ready_machine();
  const json s = run_to_end(
      "M64 P1\n"
      "M66 P0 L3 Q2\n"
      "o1 if [#5399 EQ 1]\n"
      "  G0 X1\n"
      "o1 endif\n"
      "M66 P2 L3 Q0.3\n"
      "o2 if [#5399 EQ -1]\n"
      "  G0 Y7\n"
      "o2 endif\n"
      "M2\n");
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 1.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 7.0);
  EXPECT_EQ(s["io"]["douts"][1], true);
  EXPECT_EQ(s["io"]["dins"][0], true);
}

}  // namespace
}  // namespace cncd::test
