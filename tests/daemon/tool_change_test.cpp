// M6 on the real daemon: the program waits for the operator (status "wait"), tool.change_done
// and cncctl answer it, abort during the wait stops cleanly.
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

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

// A command on a pseudo-terminal, as an operator at a console runs it.
class OnTerminal {
 public:
  explicit OnTerminal(const std::vector<std::string>& argv) {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) return;
    const std::string slave_name = ::ptsname(master_);
    std::vector<char*> args;
    for (const auto& arg : argv)
      args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::setsid();
      const int slave = ::open(slave_name.c_str(), O_RDWR);
      if (slave < 0) ::_exit(126);
      for (int fd = 0; fd < 3; ++fd)
        ::dup2(slave, fd);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
  }
  ~OnTerminal() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (master_ >= 0) ::close(master_);
  }
  bool ok() const { return master_ >= 0 && pid_ > 0; }
  bool type(const std::string& text) {
    return ::write(master_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  }
  // Reads what it has written until `text` is among it or `limit` has passed.
  bool wait_for(const std::string& text, std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (output_.find(text) == std::string::npos) {
      if (std::chrono::steady_clock::now() > deadline || !read_some()) return false;
    }
    return true;
  }
  // Its exit status once it has ended (-1 when it has not within a minute), reading its
  // output meanwhile.
  int wait() {
    int status = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      // Once the terminal has closed, poll() no longer waits: the process may still be on its
      // way out.
      if (!read_some()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  const std::string& output() const { return output_; }

 private:
  // Waits up to 50 ms for output and keeps it; false once the terminal has closed.
  bool read_some() {
    pollfd fd{master_, POLLIN, 0};
    if (::poll(&fd, 1, 50) <= 0) return true;
    char buffer[512];
    const ssize_t n = ::read(master_, buffer, sizeof buffer);
    if (n <= 0) return false;
    output_.append(buffer, static_cast<std::size_t>(n));
    return true;
  }

  int master_ = -1;
  pid_t pid_ = -1;
  std::string output_;
};

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
  result_of(call("tool.change_done", {{"tool", 3}}));
  const json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done["program"].dump();
  EXPECT_EQ(done["position"]["commanded"]["x"], 10.0);
  EXPECT_EQ(done["tool"]["number"], 3);
  EXPECT_TRUE(done["wait"].is_null());
}

TEST_F(ToolChange, NothingToAnswerIsRefused) {
  ready_machine();
  EXPECT_EQ(error_code(call("tool.change_done", {{"tool", 3}})), 1001);
}

// An answer is for one tool: one meant for another change (a second Enter, a confirmation
// sent before the prompt was seen) does not let the program go on.
TEST_F(ToolChange, TheAnswerNamesTheToolThePromptAsksFor) {
  ready_machine();
  start_program("two.ngc", "T3 M6\nG0 X5\nT2 M6\nG0 X10\nM2\n");
  wait_until(waiting_for_tool);
  EXPECT_EQ(error_code(call("tool.change_done")), -32602);  // the tool is required
  const json wrong = call("tool.change_done", {{"tool", 2}});
  EXPECT_EQ(error_code(wrong), -32602);
  EXPECT_EQ(wrong["error"].value("message", ""), "the tool change waiting is for T3, not T2");
  EXPECT_EQ(status()["wait"]["tool"], 3);
  result_of(call("tool.change_done", {{"tool", 3}}));
  const json second =
      wait_until([](const json& s) { return waiting_for_tool(s) && s["wait"]["tool"] == 2; });
  EXPECT_EQ(second["position"]["commanded"]["x"], 5.0);
  // The first change's answer again, late: refused, and the second change still waits.
  const json late = call("tool.change_done", {{"tool", 3}});
  EXPECT_EQ(error_code(late), -32602);
  EXPECT_EQ(late["error"].value("message", ""), "the tool change waiting is for T2, not T3");
  EXPECT_TRUE(waiting_for_tool(status()));
  result_of(call("tool.change_done", {{"tool", 2}}));
  const json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done["program"].dump();
  EXPECT_EQ(done["position"]["commanded"]["x"], 10.0);
  EXPECT_EQ(done["tool"]["number"], 2);
}

// Run from a line past an M6: the tool the skipped M6 named goes in first, as an M6 would
// put it in, and only then does the machine move with its length.
TEST_F(ToolChange, RunFromLinePastAnM6ChangesToThatToolFirst) {
  ready_machine();
  const std::string program =
      "G21 G90 G49\n"
      "G0 X0 Y0 Z50\n"
      "T3 M6\n"
      "G43 H3\n"
      "G0 X10 Z1\n"
      "G0 X20\n"
      "M2\n";
  const auto path = dir_.write("from.ngc", program);
  result_of(call("program.open", {{"path", path.string()}}));
  const json before = status();
  EXPECT_EQ(before["tool"]["number"], 0);
  result_of(call("program.run", {{"from_line", 5}}));
  const json waiting =
      wait_until([](const json& s) { return waiting_for_tool(s) || s["exec"] == "idle"; });
  ASSERT_TRUE(waiting_for_tool(waiting))
      << "ran with T3's length and T0 in the spindle: " << waiting.dump();
  EXPECT_EQ(waiting["wait"]["tool"], 3);
  EXPECT_EQ(waiting["wait"]["message"], "Insert T3 (10 mm face mill) and press Enter");
  // Nothing has moved yet.
  EXPECT_EQ(waiting["position"]["commanded"], before["position"]["commanded"]);
  result_of(call("tool.change_done", {{"tool", 3}}));
  json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done["program"].dump();
  EXPECT_EQ(done["position"]["commanded"]["x"], 20.0);
  EXPECT_EQ(done["position"]["commanded"]["z"], 26.0);  // Z1 + T3's 25 mm
  EXPECT_EQ(done["tool"]["number"], 3);
  // With T3 in the spindle the same run asks for nothing.
  result_of(call("program.run", {{"from_line", 5}}));
  done = wait_until([](const json& s) { return waiting_for_tool(s) || s["exec"] == "idle"; });
  EXPECT_FALSE(waiting_for_tool(done));
  EXPECT_EQ(done["program"]["result"], "done") << done["program"].dump();
  EXPECT_EQ(done["position"]["commanded"]["z"], 26.0);
}

// The length G43 applies after an aborted run is that of the tool in the spindle, never of a
// tool the run read of but never got: else the next move goes to the wrong height.
TEST_F(ToolChange, AnAbortedRunFromLineLeavesTheToolThatIsIn) {
  ready_machine();
  mdi("G43");  // T0: no length
  const auto path =
      dir_.write("from.ngc", "G21 G90\nG0 X0 Y0 Z50\nT3 M6\nG43 H3\nG0 X10 Z1\nG0 X20\nM2\n");
  result_of(call("program.open", {{"path", path.string()}}));
  result_of(call("program.run", {{"from_line", 5}}));
  wait_until([](const json& s) { return waiting_for_tool(s) || s["exec"] == "idle"; });
  result_of(call("program.abort"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["tool"]["number"], 0) << s["tool"].dump();
  EXPECT_EQ(s["tool"]["length_offset"]["z"], 0.0) << s["tool"].dump();
  mdi("G0 Z5");
  EXPECT_EQ(status()["position"]["commanded"]["z"], 5.0);
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
  EXPECT_EQ(error_code(call("tool.change_done", {{"tool", 3}})), 1001);
  // T3 was never put in: the tool in the spindle, and the length G43 applies, are as before.
  EXPECT_EQ(s["tool"]["number"], 0) << s["tool"].dump();
  mdi("G43 G0 Z0");
  EXPECT_EQ(status()["position"]["commanded"]["z"], 0.0);
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

// An Enter typed before the prompt (for the last change, or by accident) does not answer it.
TEST_F(ToolChange, CncctlOnATerminalDiscardsWhatWasTypedBeforeThePrompt) {
  ready_machine();
  const auto program = dir_.write("ahead.ngc", "G4 P0.5\nT3 M6\nG0 X10\nM2\n");
  OnTerminal run({CNCCTL_BINARY, "--socket", daemon_.socket(), "run", program.string()});
  ASSERT_TRUE(run.ok());
  ASSERT_TRUE(run.type("\n"));  // typed ahead, while the dwell runs
  ASSERT_TRUE(run.wait_for("Insert T3", std::chrono::seconds(60))) << run.output();
  // Still waiting half a second into the change: the Enter typed ahead was dropped.
  const json s = wait_until([](const json& st) {
    return st["exec"] == "idle" || (waiting_for_tool(st) && st["wait"]["since"] > 0.5);
  });
  EXPECT_TRUE(waiting_for_tool(s)) << s.dump();
  ASSERT_TRUE(run.type("\n"));
  EXPECT_EQ(run.wait(), 0) << run.output();
  EXPECT_EQ(status()["program"]["result"], "done");
}

TEST_F(ToolChange, CncctlToolDoneAnswersFromAnotherTerminal) {
  ready_machine();
  start_program("change.ngc", kProgram);
  wait_until(waiting_for_tool);
  EXPECT_EQ(cncctl({"tool-done"}).exit_status, 64);  // the tool must be named
  const CommandResult wrong = cncctl({"tool-done", "T2"});
  EXPECT_EQ(wrong.exit_status, 2);
  EXPECT_NE(wrong.err.find("waiting is for T3, not T2"), std::string::npos) << wrong.err;
  const CommandResult done = cncctl({"tool-done", "T3"});
  EXPECT_EQ(done.exit_status, 0) << done.err;
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  const CommandResult again = cncctl({"tool-done", "3"});
  EXPECT_NE(again.exit_status, 0);
  EXPECT_NE(again.err.find("no tool change is waiting"), std::string::npos) << again.err;
}

}  // namespace
}  // namespace cncd::test
