// cncctl against the real daemon: the setup, step, run-from-line and watch commands, --json and
// the exit codes (0 done, 1 failed, 2 refused, 64 usage, 69 unreachable).
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class CncctlTest : public MachineTest {
 protected:
  void ready() {
    for (const char* command : {"reset", "on", "home"})
      ASSERT_EQ(cncctl({command}).exit_status, 0) << command;
  }
};

TEST_F(CncctlTest, ToolsListsAndSets) {
  auto r = cncctl({"tools"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("3 mm drill"), std::string::npos) << r.out;
  r = cncctl({"tools", "set", "T2", "Z12.5", "D3.2", ";3.2", "mm", "drill"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = cncctl({"--json", "tools"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const json list = json::parse(r.out);
  EXPECT_EQ(list["tools"][1]["offset"]["z"], 12.5);
  EXPECT_EQ(list["tools"][1]["diameter"], 3.2);
  EXPECT_EQ(list["tools"][1]["comment"], "3.2 mm drill");
  r = cncctl({"tools", "set", "T0", "Z1"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("\"number\" must be an integer from 1"), std::string::npos) << r.err;
  EXPECT_EQ(cncctl({"tools", "set", "Z1"}).exit_status, 64);
  EXPECT_EQ(cncctl({"tools", "set", "T1", "Zfoo"}).exit_status, 64);
}

TEST_F(CncctlTest, OffsetsListsAndSets) {
  auto r = cncctl({"offsets", "set", "G55", "X5", "Z-2.5"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = cncctl({"offsets"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("G55     X 5.0000  Y 0.0000  Z -2.5000"), std::string::npos) << r.out;
  r = cncctl({"--json", "offsets"});
  EXPECT_EQ(json::parse(r.out)["systems"][1]["origin"]["x"], 5.0);
  EXPECT_EQ(cncctl({"offsets", "set", "G60", "X1"}).exit_status, 2);
  EXPECT_EQ(cncctl({"offsets", "set", "G55", "K1"}).exit_status, 64);
}

TEST_F(CncctlTest, StepAndRunFromLine) {
  ready();
  const auto program = dir_.write("p.ngc", "G21 G90\nG0 X1\nG1 F600 X5\nM2\n");
  auto r = cncctl({"step", program.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("line 1/4"), std::string::npos) << r.out;
  r = cncctl({"step"});
  EXPECT_NE(r.out.find("line 2/4  X 1.0000"), std::string::npos) << r.out;
  r = cncctl({"--json", "step"});
  EXPECT_EQ(json::parse(r.out)["position"]["commanded"]["x"], 5.0);
  EXPECT_EQ(cncctl({"run", program.string()}).exit_status, 2);  // still stepping
  EXPECT_EQ(cncctl({"abort"}).exit_status, 0);
  r = cncctl({"run", program.string(), "--from", "3"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("done"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[###############     ]  75%  line 3/4"), std::string::npos) << r.out;
  EXPECT_EQ(cncctl({"run", program.string(), "--from", "9"}).exit_status, 2);
  EXPECT_EQ(cncctl({"run", program.string(), "--from", "x"}).exit_status, 64);
}

TEST_F(CncctlTest, WatchPrintsUpdatesAndStopsOnInterrupt) {
  // Updates come when the status changes: the first (full) one always.
  auto r = cncctl({"--json", "watch", "--interval", "20", "--count", "1"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) {
    EXPECT_EQ(json::parse(line)["state"], "estop") << line;
    ++count;
  }
  EXPECT_EQ(count, 1);
  r = cncctl({"watch", "--count", "1"});
  EXPECT_NE(r.out.find("state     estop"), std::string::npos) << r.out;
  // Ctrl-C ends a watch cleanly (exit 0, not killed by the signal).
  r = run_command({"/usr/bin/timeout", "--preserve-status", "-s", "INT", "0.5", CNCCTL_BINARY,
                   "--socket", daemon_.socket(), "watch"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("state     estop"), std::string::npos) << r.out;
  EXPECT_EQ(cncctl({"watch", "--count", "0"}).exit_status, 64);
}

TEST_F(CncctlTest, OverrideSetsPercentagesAndStatusShowsThem) {
  auto r = cncctl({"override", "feed", "50"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.out, "feed override 50 %\n");
  r = cncctl({"--json", "override", "spindle", "120%"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["value"], 1.2);
  EXPECT_EQ(cncctl({"override", "rapid", "25"}).exit_status, 0);
  r = cncctl({"status"});
  EXPECT_NE(r.out.find("override  feed 50 %  rapid 25 %  spindle 120 %"), std::string::npos)
      << r.out;
  r = cncctl({"override", "feed", "200"});  // above MAX_FEED_OVERRIDE 1.5
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("from 0 to 1.5"), std::string::npos) << r.err;
  EXPECT_EQ(cncctl({"override", "feed", "fast"}).exit_status, 64);
  EXPECT_EQ(cncctl({"override", "coolant", "50"}).exit_status, 64);
  EXPECT_EQ(cncctl({"override", "feed"}).exit_status, 64);
  EXPECT_EQ(json::parse(cncctl({"--json", "status"}).out)["overrides"]["feed"], 0.5);
}

TEST_F(CncctlTest, InfoAndErrorsSince) {
  auto r = cncctl({"info"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("machine   cncd sim mill (mm)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("axes      X Y Z (mm)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("joints    3: sim sim sim"), std::string::npos) << r.out;
  r = cncctl({"--json", "info"});
  EXPECT_EQ(json::parse(r.out)["protocol_version"], 1);
  EXPECT_EQ(cncctl({"info", "extra"}).exit_status, 64);
  // Two events, then only those after the first.
  ASSERT_EQ(cncctl({"tools", "set", "T2", "Z1"}).exit_status, 0);
  ASSERT_EQ(cncctl({"tools", "set", "T3", "Z2"}).exit_status, 0);
  const json all = json::parse(cncctl({"--json", "errors"}).out);
  ASSERT_GE(all["events"].size(), 2u);
  const auto first = all["events"][all["events"].size() - 2]["seq"].get<unsigned long long>();
  r = cncctl({"--json", "errors", "--since", std::to_string(first)});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  const json later = json::parse(r.out);
  ASSERT_EQ(later["events"].size(), 1u) << r.out;
  EXPECT_EQ(later["events"][0]["message"], "tool 3 changed");
  EXPECT_EQ(cncctl({"errors", "--since", "x"}).exit_status, 64);
  EXPECT_EQ(cncctl({"errors", "--since", "-1"}).exit_status, 64);
  EXPECT_EQ(cncctl({"errors", "all"}).exit_status, 64);
}

TEST_F(CncctlTest, ExitCodesTellDoneRefusedFailedAndUnreachable) {
  auto r = cncctl({"--json", "estop"});
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(json::parse(r.out)["ok"], true);
  EXPECT_EQ(cncctl({"on"}).exit_status, 2);  // in estop
  ready();
  // program.open refuses a program the interpreter stops on, naming the line.
  const auto bad = dir_.write("bad.ngc", "G21 G90\nG1 X5\nM2\n");  // no feed rate
  r = cncctl({"run", bad.string()});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("bad.ngc:2"), std::string::npos) << r.err;
  // A run that fails: from a line after the program's end.
  const auto ends = dir_.write("ends.ngc", "G21 G90\nM2\nG0 X5\nG0 X6\n");
  r = cncctl({"run", ends.string(), "--from", "4"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE((r.err + r.out).find("ends at line 2, before line 4"), std::string::npos)
      << r.err << r.out;
  EXPECT_EQ(cncctl({"frobnicate"}).exit_status, 64);
  r = run_command({CNCCTL_BINARY, "--socket", (dir_.path() / "none.sock").string(), "status"});
  EXPECT_EQ(r.exit_status, 69);
}

// Text from cncd goes to a terminal: a program's (MSG, ...) and a file name must not carry
// escape sequences there (retitle the window, move the cursor, hide what follows).
TEST_F(CncctlTest, ControlCharactersFromTheProgramAreEscaped) {
  ready();
  const std::string hostile =
      "\x1b]0;owned\x07 \x1b[2J \xc2\x9b"
      "31m \x7f \xff caf\xc3\xa9\tend";
  const auto program = dir_.write("msg\x1b[1m.ngc", "(MSG, " + hostile + ")\nG0 X1\nM2\n");
  auto r = cncctl({"run", program.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  for (const auto* command : {"errors", "status"}) {
    r = cncctl({command});
    EXPECT_EQ(r.exit_status, 0) << r.err;
    for (const char bad : {'\x1b', '\x07', '\x7f', '\t'})
      EXPECT_EQ(r.out.find(bad), std::string::npos) << command << ": " << r.out;
    EXPECT_EQ(r.out.find("\xc2\x9b"), std::string::npos) << command << ": " << r.out;
    EXPECT_EQ(r.out.find('\xff'), std::string::npos) << command << ": " << r.out;
    EXPECT_NE(r.out.find("msg\\x1b[1m.ngc"), std::string::npos) << command << ": " << r.out;
  }
  r = cncctl({"errors"});
  // Printable UTF-8 stays as it is; what is not is written so that it can be read (cncd's JSON
  // has made the stray byte U+FFFD).
  EXPECT_NE(
      r.out.find("\\x1b]0;owned\\x07 \\x1b[2J \\u009b31m \\x7f \xef\xbf\xbd caf\xc3\xa9\\tend"),
      std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace cncd::test
