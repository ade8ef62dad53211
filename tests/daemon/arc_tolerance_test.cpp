// Arcs whose centre words are rounded (the end a little off the start's circle): cncd-check,
// cncd-check --plan, program.open and program.run give the same verdict at the same line. Within
// LinuxCNC's tolerance they run to their end on the sim machine; a 0.2 mm difference is
// refused by all of them at the arc's line.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class ArcToleranceTest : public MachineTest {
 protected:
  CommandResult check(const std::filesystem::path& program, bool plan = false) {
    std::vector<std::string> argv{CNCD_CHECK_BINARY, "--ini", ini_.string()};
    if (plan) argv.push_back("--plan");
    argv.push_back(program.string());
    return run_command(argv);
  }

  // Checks, opens and runs `text`; the run must end "done" at (x, y, z).
  void runs_to_its_end(const std::string& text, double x, double y, double z) {
    const auto program = dir_.write("rounded.ngc", text);
    const auto checked = check(program);
    EXPECT_EQ(checked.exit_status, 0) << checked.err;
    const auto planned = check(program, true);
    EXPECT_EQ(planned.exit_status, 0) << planned.err << planned.out;
    result_of(call("program.open", {{"path", program.string()}}));
    result_of(call("program.run"));
    const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    EXPECT_EQ(s["program"]["result"], "done") << s.dump();
    const auto& pos = s["position"]["commanded"];
    EXPECT_EQ(pos["x"].get<double>(), x) << s.dump();
    EXPECT_EQ(pos["y"].get<double>(), y);
    EXPECT_EQ(pos["z"].get<double>(), z);
  }
};

TEST_F(ArcToleranceTest, ArcsWithRoundedCentreWordsRunToTheirEnd) {
  ready_machine();
  // The end is 2.5 um off the start's circle of radius 0.2.
  runs_to_its_end("G21 G90 G17 G94\nG0 X10 Y10 Z5\nG1 Z0 F600\nG3 X10.2 Y10.199 I0 J0.2\nM2\n",
                  10.2, 10.199, 0);
  // 10 um off a radius of 5.005, from X0 Y0.
  runs_to_its_end("G21 G90 G17 G94\nG0 X0 Y0 Z0\nG2 X10 Y0 I5.005 J0 F600\nM2\n", 10, 0, 0);
}

TEST_F(ArcToleranceTest, ARadiusDifferenceBeyondTheToleranceIsRefusedAtItsLineEverywhere) {
  ready_machine();
  const std::string bad = "G21 G90 G17 G94\nG0 X0 Y0 Z0\nG1 Z-1 F600\nG2 X10 Y0 I5.1 J0\nM2\n";
  const std::string message = "Radius to end of arc differs from radius to start";
  const auto program = dir_.write("mismatch.ngc", bad);
  const std::string at_line = program.string() + ":4:";

  const auto checked = check(program);
  EXPECT_EQ(checked.exit_status, 1);
  EXPECT_NE(checked.err.find(at_line), std::string::npos) << checked.err;
  EXPECT_NE(checked.err.find(message), std::string::npos) << checked.err;
  const auto planned = check(program, true);
  EXPECT_NE(planned.exit_status, 0);
  EXPECT_NE(planned.err.find(at_line), std::string::npos) << planned.err;

  const json opened = call("program.open", {{"path", program.string()}});
  EXPECT_EQ(error_code(opened), 1003);
  const std::string open_error = opened["error"].value("message", "");
  EXPECT_NE(open_error.find(at_line), std::string::npos) << open_error;
  EXPECT_NE(open_error.find(message), std::string::npos) << open_error;

  // A file changed on disk after it was opened: the run stops at the same line, and the arc
  // moves nothing.
  dir_.write("mismatch.ngc", "G21 G90\nG0 X1\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  dir_.write("mismatch.ngc", bad);
  result_of(call("program.run"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "error") << s.dump();
  const std::string run_error = s["program"]["error"];
  EXPECT_NE(run_error.find(at_line), std::string::npos) << run_error;
  EXPECT_NE(run_error.find(message), std::string::npos) << run_error;
  EXPECT_EQ(s["position"]["commanded"]["x"].get<double>(), 0.0);
}

}  // namespace
}  // namespace cncd::test
