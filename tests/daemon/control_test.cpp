// The priority path (pause whatever is queued), machine.off during a program, status.unsubscribe
// and cncctl's pause, resume and off against the real daemon.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// Hundreds of 10 mm moves at 50 mm/s: the queue holds far more than the time a pause may take.
std::string back_and_forth(int moves) {
  std::string program = "G21 G90 G1 F3000\n";
  for (int i = 0; i < moves; ++i)
    program += i % 2 == 0 ? "X10\n" : "X0\n";
  return program + "M2\n";
}

TEST_F(MachineTest, PauseStopsAtOnceWhateverIsQueued) {
  ready_machine();
  const auto program = dir_.write("many.ngc", back_and_forth(400));
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  wait_until([](const json& s) { return s["velocity"].get<double>() > 20.0; });
  const auto asked = Clock::now();
  result_of(call("program.pause"));
  json s = wait_until([](const json& st) { return st["motion"] == "paused"; });
  // Stopping from 50 mm/s at 2000 mm/s^2 takes 25 ms; the queued moves would take a minute.
  EXPECT_LT(Clock::now() - asked, std::chrono::milliseconds(1000));
  EXPECT_EQ(s["exec"], "paused");
  EXPECT_EQ(s["velocity"], 0.0);
  const json held = s["position"]["commanded"];
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_EQ(status()["position"]["commanded"], held);
  result_of(call("program.resume"));
  s = wait_until([](const json& st) { return st["velocity"].get<double>() > 0.0; });
  EXPECT_EQ(s["exec"], "running");
  result_of(call("program.abort"));
  EXPECT_EQ(status()["program"]["result"], "aborted");
}

TEST_F(MachineTest, MachineOffEndsAProgramAndStopsTheMachine) {
  ready_machine();
  start_program("long.ngc", "G21 G90 G1 F600 X100\nM2\n");
  wait_until([](const json& s) { return s["position"]["commanded"]["x"].get<double>() > 0.5; });
  result_of(call("machine.off"));
  json s = status();
  EXPECT_EQ(s["state"], "off");
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["program"]["result"], "aborted");
  const double x = s["position"]["commanded"]["x"].get<double>();
  EXPECT_LT(x, 100.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(status()["position"]["commanded"]["x"].get<double>(), x);
  // Off is not estop: on again without a reset.
  result_of(call("machine.on"));
  EXPECT_EQ(status()["state"], "on");
  const json after = status();
  for (const auto& homed : after["homed"])
    EXPECT_TRUE(homed.get<bool>());
}

TEST_F(MachineTest, UnsubscribeEndsTheUpdates) {
  result_of(call("status.subscribe", {{"interval_ms", 10}}));
  json first;
  do {
    first = json::parse(client_.read_line(5000));
  } while (first.value("method", "") != "status.update");
  EXPECT_EQ(result_of(call("status.unsubscribe")), (json{{"ok", true}}));
  result_of(call("machine.reset"));  // a change a subscriber would be sent
  const auto until = Clock::now() + std::chrono::milliseconds(300);
  while (Clock::now() < until) {
    const auto line = client_.try_read_line(50);
    if (!line) continue;
    EXPECT_NE(json::parse(*line).value("method", ""), "status.update") << *line;
  }
}

TEST_F(MachineTest, CncctlPauseResumeAndOff) {
  ready_machine();
  const auto program = dir_.write("many.ngc", back_and_forth(400));
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const auto cncctl = [&](const std::string& command) {
    return run_command({CNCCTL_BINARY, "--socket", daemon_.socket(), command});
  };
  auto r = cncctl("pause");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(wait_until([](const json& s) { return s["motion"] == "paused"; })["exec"], "paused");
  EXPECT_EQ(cncctl("pause").exit_status, 2);  // not running
  EXPECT_EQ(cncctl("resume").exit_status, 0);
  EXPECT_EQ(status()["exec"], "running");
  EXPECT_EQ(cncctl("resume").exit_status, 2);  // not paused
  EXPECT_EQ(cncctl("off").exit_status, 0);
  const json s = status();
  EXPECT_EQ(s["state"], "off");
  EXPECT_EQ(s["program"]["result"], "aborted");
}

}  // namespace
}  // namespace cncd::test
