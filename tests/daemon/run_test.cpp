// program.run {from_line} and program.step against the real daemon.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

TEST_F(MachineTest, RunFromLineKeepsModalStateOffsetsAndSkipsMotion) {
  ready_machine();
  const auto program = dir_.write("part.ngc",
                                  "G21 G90\n"
                                  "G10 L2 P1 X10\n"
                                  "G0 X5 Y5\n"
                                  "G91 M0\n"
                                  "G1 F1200 X1 Y1\n"
                                  "G90 G0 X0\n"
                                  "M2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run", {{"from_line", 5}}));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  // The way to where line 5 starts (X15 Y5 in machine coordinates: Z up to the safe height,
  // X and Y over it, Z down), line 5 (G91 kept: to X16 Y6), line 6 (G54 X0 with the origin
  // set on line 2: machine X10). The skipped G0 of line 3 and the M0 of line 4 did nothing.
  EXPECT_EQ(s["program"]["moves"], 5);
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 6.0, 1e-9);
  EXPECT_EQ(s["offsets"]["g5x"]["x"], 10.0);
}

TEST_F(MachineTest, ACompensatedProgramRunsToItsEndOnTheOffsetPath) {
  ready_machine();
  // A 4 mm tool on the left of a three-sided pocket wall: each move waits for the next one to
  // fix the inside corner, and G40 sends the last.
  const auto program = dir_.write("comp.ngc",
                                  "G21 G90\n"
                                  "G0 X10 Y10\n"
                                  "F1200\n"
                                  "G41.1 D4\n"
                                  "G1 X20 Y10\n"
                                  "G1 X20 Y20\n"
                                  "G1 X10 Y20\n"
                                  "G40\n"
                                  "G0 X5 Y5\n"
                                  "M2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run", json::object()));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  // The rapid in, the three compensated feeds (to X18 Y12, X18 Y18, X10 Y18), the rapid out.
  EXPECT_EQ(s["program"]["moves"], 5);
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 5.0, 1e-9);
}

TEST_F(MachineTest, RunFromLineOutsideTheProgramIsRefused) {
  ready_machine();
  const auto program = dir_.write("short.ngc", "G21 G90\nG0 X1\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  const json past = call("program.run", {{"from_line", 4}});
  EXPECT_EQ(error_code(past), -32602);
  EXPECT_NE(past["error"].value("message", "").find("from 1 to 3"), std::string::npos)
      << past.dump();
  EXPECT_EQ(error_code(call("program.run", {{"from_line", 0}})), -32602);
  EXPECT_EQ(error_code(call("program.run", {{"from_line", "2"}})), -32602);
  EXPECT_EQ(status()["exec"], "idle");
}

TEST_F(MachineTest, RunFromALineAfterTheProgramEndFails) {
  ready_machine();
  const auto program = dir_.write("ends.ngc", "G21 G90\nM2\nG0 X5\nG0 X6\n");
  result_of(call("program.open", {{"path", program.string()}}));
  // It ends before anything moves: the request's answer says so.
  const json r = call("program.run", {{"from_line", 4}});
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_NE(r.dump().find("ends at line 2, before line 4"), std::string::npos) << r.dump();
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "error");
  EXPECT_NE(s["program"]["error"].get<std::string>().find("ends at line 2, before line 4"),
            std::string::npos)
      << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 0.0);
}

TEST_F(MachineTest, StepRunsOneLineAtATimeAndResumeRunsOn) {
  ready_machine();
  start_program("steps.ngc", "G21 G90 G0 X1\nG0 X2\nG0 X3\nG0 X4\nM2\n", "program.step");
  json s = wait_until([](const json& st) { return st["exec"] == "paused"; });
  EXPECT_EQ(s["position"]["commanded"]["x"], 1.0);
  EXPECT_EQ(s["program"]["stepping"], true);
  EXPECT_EQ(s["motion"], "idle");
  // Still there a moment later: nothing more was read.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(status()["position"]["commanded"]["x"], 1.0);
  result_of(call("program.step"));
  s = wait_until([](const json& st) {
    return st["exec"] == "paused" && st["position"]["commanded"]["x"] == 2.0;
  });
  EXPECT_EQ(s["program"]["moves"], 2);
  result_of(call("program.resume"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_EQ(s["program"]["stepping"], false);
  EXPECT_EQ(s["position"]["commanded"]["x"], 4.0);
}

TEST_F(MachineTest, StepWhileAStepRunsIsRefused) {
  ready_machine();
  start_program("long.ngc", "G21 G90 G1 F600 X50\nG0 X0\nM2\n", "program.step");
  EXPECT_EQ(error_code(call("program.step")), 1004);
  result_of(call("program.abort"));
  EXPECT_EQ(status()["program"]["result"], "aborted");
}

TEST_F(MachineTest, AFanucStyleProgramNumberLineIsIgnoredAsLinuxCncDoes) {
  ready_machine();
  // As Fanuc-style posts write it: %, the program number with its name, the program, %.
  const auto program =
      dir_.write("o0001.ngc", "%\nO0001 (BRACKET)\nG21 G90 G17\nG0 X12 Y7 Z3\nM30\n%\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const auto s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 12.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 7.0);
}

TEST_F(MachineTest, M60PausesLikeM0AndResumeRunsOn) {
  ready_machine();
  start_program("m60.ngc", "G21 G90\nG0 X5\nM60\nG0 X9\nM2\n");
  auto s = wait_until([](const json& st) { return st["exec"] == "paused"; });
  EXPECT_EQ(s["position"]["commanded"]["x"], 5.0);
  result_of(call("program.resume"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 9.0);
}

// A subroutine file has its own line numbers: while it runs, the program's line is the call's
// and the progress never passes the program's length.
TEST_F(MachineTest, ASubroutineFileCountsAsItsCallLineInTheProgress) {
  ready_machine();
  std::string far = "o<far> sub\n";
  for (int i = 1; i <= 40; ++i)
    far += "G1 X" + std::to_string(i % 2 ? 2 : 0) + " F6000\n";
  dir_.write("far.ngc", far + "o<far> endsub\nM2\n");
  start_program("caller.ngc", "G21 G90\no<far> call\nG0 X5\nM2\n");
  bool saw_call_line = false;
  for (;;) {
    const json s = status();
    const int line = s["program"]["line"];
    EXPECT_LE(line, 4) << s.dump();
    EXPECT_LE(s["program"]["progress"].get<double>(), 1.0);
    if (s["exec"] == "running" && line == 2 && s["motion"] == "moving") saw_call_line = true;
    if (s["exec"] == "idle") {
      EXPECT_EQ(s["program"]["result"], "done") << s.dump();
      break;
    }
  }
  EXPECT_TRUE(saw_call_line);
}

}  // namespace
}  // namespace cncd::test
