// M6 on the real daemon: the program waits for the operator (status "wait"), tool.change_done
// and cncctl answer it, abort during the wait stops cleanly.
#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr const char* kProgram =
    "G0 X0 Y0 Z5\n"
    "M3 S1000\n"
    "M8\n"
    "T3 M6\n"
    "G0 X10\n"
    "M2\n";

bool waiting_for_tool(const json& s) {
  return s["wait"].is_object() && s["wait"].value("kind", "") == "tool_change";
}

class ToolChange : public MachineTest {};

TEST_F(ToolChange, M6WaitsForTheOperatorThenGoesOn) {
  ready_machine();
  start_program("change.ngc", kProgram);
  const json waiting = wait_until(waiting_for_tool);
  EXPECT_EQ(waiting["wait"]["tool"], 3);
  EXPECT_EQ(waiting["wait"]["message"], "Insert T3 (10 mm face mill) and press Enter");
  EXPECT_EQ(waiting["exec"], "running");
  // The interpreter stopped the spindle for the change; coolant stays as the program set it.
  EXPECT_EQ(waiting["spindle"]["enabled"], false);
  EXPECT_EQ(waiting["coolant"]["flood"], true);
  // It stays there.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const json still = status();
  EXPECT_TRUE(waiting_for_tool(still));
  EXPECT_EQ(still["position"]["commanded"]["x"], 0.0);
  EXPECT_GT(still["wait"]["since"].get<double>(), 0.2);
  result_of(call("tool.change_done"));
  const json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done["program"].dump();
  EXPECT_EQ(done["position"]["commanded"]["x"], 10.0);
  EXPECT_EQ(done["tool"]["number"], 3);
  EXPECT_TRUE(done["wait"].is_null());
}

TEST_F(ToolChange, NothingToAnswerIsRefused) {
  ready_machine();
  EXPECT_EQ(error_code(call("tool.change_done")), 1001);
}

TEST_F(ToolChange, AbortDuringTheWaitStopsCleanly) {
  ready_machine();
  start_program("change.ngc", kProgram);
  wait_until(waiting_for_tool);
  result_of(call("program.abort"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "aborted");
  EXPECT_TRUE(s["wait"].is_null());
  EXPECT_EQ(s["state"], "on");
  EXPECT_EQ(s["coolant"]["flood"], false);
  EXPECT_EQ(s["position"]["commanded"]["x"], 0.0);
  EXPECT_EQ(error_code(call("tool.change_done")), 1001);
}

TEST_F(ToolChange, CncctlRunPromptsAndEnterAnswers) {
  ready_machine();
  const auto program = dir_.write("change.ngc", kProgram);
  BackgroundCommand run({CNCCTL_BINARY, "--socket", daemon_.socket(), "run", program.string()});
  wait_until(waiting_for_tool);
  // The prompt comes before the answer is read.
  for (int i = 0; i < 200 && run.err_so_far().find("Insert T3") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_NE(run.err_so_far().find("Insert T3 (10 mm face mill) and press Enter"),
            std::string::npos);
  ASSERT_TRUE(run.write_stdin("\n"));
  const CommandResult result = run.wait();
  EXPECT_EQ(result.exit_status, 0) << result.err;
  EXPECT_NE(result.out.find("done in"), std::string::npos) << result.out;
}

TEST_F(ToolChange, CncctlToolDoneAnswersFromAnotherTerminal) {
  ready_machine();
  start_program("change.ngc", kProgram);
  wait_until(waiting_for_tool);
  const CommandResult done = cncctl({"tool-done"});
  EXPECT_EQ(done.exit_status, 0) << done.err;
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  const CommandResult again = cncctl({"tool-done"});
  EXPECT_NE(again.exit_status, 0);
  EXPECT_NE(again.err.find("no tool change is waiting"), std::string::npos) << again.err;
}

}  // namespace
}  // namespace cncd::test
