// The real cncd refuses, with exit status 78 and the INI line, a configuration that loads but
// cannot work here: start-up code that the interpreter rejects or that moves the machine, and
// state files it could not write. cncd-check refuses the start-up code too.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "daemon_process.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;

// Lines of config/examples/sim_mm.ini.
constexpr int kStartupCodeLine = 25;
constexpr int kToolTableLine = 29;

class StartChecksTest : public ::testing::Test {
 protected:
  // The example machine with the line `KEY = ...` replaced by `KEY = value`.
  fs::path machine_with(const std::string& key, const std::string& value) {
    const fs::path ini = copy_example_machine(dir_.path());
    std::ifstream in(ini);
    std::ostringstream out;
    std::string line;
    bool replaced = false;
    while (std::getline(in, line)) {
      if (line.starts_with(key + " ")) {
        line = key + " = " + value;
        replaced = true;
      }
      out << line << '\n';
    }
    EXPECT_TRUE(replaced) << key;
    std::ofstream(ini) << out.str();
    return ini;
  }
  CommandResult check_config(const fs::path& ini, const fs::path& state_dir) {
    return run_command(
        {CNCD_BINARY, "--check-config", ini.string(), "--state-dir", state_dir.string()});
  }
  // The daemon itself: "" when it started (it is stopped again), else its exit status and
  // log. It must stop before it serves anything.
  std::string start_daemon(const fs::path& ini, const fs::path& state_dir) {
    DaemonProcess daemon;
    const std::string error =
        daemon.start(dir_.path(), {"--ini", ini.string(), "--state-dir", state_dir.string()});
    if (error.empty()) daemon.stop();
    return error.empty() ? "cncd started" : error;
  }
  // Both ways of starting refuse with `expected` on stderr.
  void expect_refused(const fs::path& ini, const fs::path& state_dir, const std::string& expected) {
    const auto checked = check_config(ini, state_dir);
    EXPECT_EQ(checked.exit_status, 78) << checked.err;
    EXPECT_NE(checked.err.find(expected), std::string::npos) << checked.err;
    const std::string started = start_daemon(ini, state_dir);
    EXPECT_NE(started.find("exited with status 78"), std::string::npos) << started;
    EXPECT_NE(started.find(expected), std::string::npos) << started;
  }
  std::string at(int line) const {
    return (dir_.path() / "sim_mm.ini").string() + ":" + std::to_string(line) + ": ";
  }

  TempDir dir_;
};

TEST_F(StartChecksTest, StartupCodeThatMovesIsRefused) {
  const std::string expected = at(kStartupCodeLine) +
                               "[RS274NGC] RS274NGC_STARTUP_CODE: it makes a rapid move, and it "
                               "runs before every program and MDI command";
  expect_refused(machine_with("RS274NGC_STARTUP_CODE", "G21 G90 G0 X10"), dir_.path(), expected);
  const auto feed = check_config(machine_with("RS274NGC_STARTUP_CODE", "G1 Z-1 F100"), dir_.path());
  EXPECT_EQ(feed.exit_status, 78);
  EXPECT_NE(feed.err.find("it makes a feed move"), std::string::npos) << feed.err;
  // Modes only: accepted, as the examples' own start-up code is.
  const auto modes = check_config(
      machine_with("RS274NGC_STARTUP_CODE", "G17 G21 G40 G49 G55 G80 G90 G94 F300"), dir_.path());
  EXPECT_EQ(modes.exit_status, 0) << modes.err;
}

TEST_F(StartChecksTest, StartupCodeTheInterpreterRejectsIsRefused) {
  const fs::path ini = machine_with("RS274NGC_STARTUP_CODE", "G17 G21 G99.7");
  const std::string expected =
      at(kStartupCodeLine) + "[RS274NGC] RS274NGC_STARTUP_CODE: the interpreter rejects it: ";
  expect_refused(ini, dir_.path(), expected);
  const auto checked =
      run_command({CNCD_CHECK_BINARY, "--ini", ini.string(), "--state-dir", dir_.path().string(),
                   std::string(CNCD_SOURCE_DIR) + "/examples/g81_example1.ngc"});
  EXPECT_EQ(checked.exit_status, 78) << checked.err;
  EXPECT_NE(checked.err.find(expected), std::string::npos) << checked.err;
}

TEST_F(StartChecksTest, StateFileInADirectoryThatDoesNotExistIsRefused) {
  const fs::path missing = dir_.path() / "no/such/dir";
  const fs::path ini = machine_with("TOOL_TABLE", (missing / "tools.tbl").string());
  expect_refused(ini, dir_.path(),
                 at(kToolTableLine) + "[EMCIO] TOOL_TABLE: directory '" + missing.string() +
                     "' does not exist");
}

TEST_F(StartChecksTest, StateDirectoryThatCncdWillCreateIsAccepted) {
  const fs::path ini = copy_example_machine(dir_.path());
  const fs::path state = dir_.path() / "state/of/the/mill";
  const auto r = check_config(ini, state);
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_.path() / "state"));  // checking writes nothing
}

TEST_F(StartChecksTest, StateDirectoryThatCannotBeCreatedIsRefused) {
  // A regular file where the state directory's parent would have to be.
  std::ofstream(dir_.path() / "plain") << "not a directory\n";
  const fs::path ini = copy_example_machine(dir_.path());
  const fs::path state = dir_.path() / "plain/state";
  expect_refused(ini, state,
                 at(22) + "[RS274NGC] PARAMETER_FILE: cannot create the state directory '" +
                     state.string() + "' (--state-dir): '" + (dir_.path() / "plain").string() +
                     "' is not a directory");
  EXPECT_NE(
      check_config(ini, state).err.find(at(kToolTableLine) + "[EMCIO] TOOL_TABLE: cannot create"),
      std::string::npos);
}

TEST_F(StartChecksTest, StateDirectoryThatIsNotWritableIsRefused) {
  const fs::path state = dir_.path() / "locked";
  fs::create_directory(state);
  ASSERT_EQ(chmod(state.c_str(), 0555), 0);
  if (access(state.c_str(), W_OK) == 0) {
    chmod(state.c_str(), 0755);
    GTEST_SKIP() << "this process may write in a mode 0555 directory (root): the check, "
                    "access(W_OK), cannot fail here";
  }
  expect_refused(copy_example_machine(dir_.path()), state,
                 "[EMCIO] TOOL_TABLE: the state directory '" + state.string() +
                     "' (--state-dir) is not writable");
  chmod(state.c_str(), 0755);
}

// A directory any user may write to lets one of them plant a link where cncd writes, or a
// parameter file of their own before cncd makes one.
TEST_F(StartChecksTest, StateDirectoryEveryUserMayWriteIsRefused) {
  const fs::path ini = copy_example_machine(dir_.path());
  for (const mode_t mode : {0777, 01777}) {
    const fs::path state = dir_.path() / ("open" + std::to_string(mode));
    fs::create_directory(state);
    ASSERT_EQ(chmod(state.c_str(), mode), 0);
    char shown[8];
    std::snprintf(shown, sizeof shown, "%04o", static_cast<unsigned>(mode));
    expect_refused(ini, state,
                   at(22) + "[RS274NGC] PARAMETER_FILE: the state directory '" + state.string() +
                       "' (--state-dir): '" + state.string() +
                       "' can be written by every user (mode " + shown + ")");
  }
  // A state directory still to be made inside /tmp-like sticky directory is cncd's own.
  const fs::path sticky = dir_.path() / "sticky";
  fs::create_directory(sticky);
  ASSERT_EQ(chmod(sticky.c_str(), 01777), 0);
  const auto r = check_config(ini, sticky / "state");
  EXPECT_EQ(r.exit_status, 0) << r.err;
}

TEST_F(StartChecksTest, StateDirectoryOfAnotherUserIsRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "giving a directory to another user needs root";
  const fs::path state = dir_.path() / "theirs";
  fs::create_directory(state);
  ASSERT_EQ(chown(state.c_str(), 65534, 65534), 0);
  expect_refused(copy_example_machine(dir_.path()), state,
                 "'" + state.string() +
                     "' belongs to uid 65534, neither cncd's user (uid 0) nor "
                     "root: its owner could replace the state files");
}

// --check-config reads the state files as the daemon does at start, and refuses what it
// refuses, at the file's line.
TEST_F(StartChecksTest, ParameterFileTheDaemonRefusesIsRefusedByCheckConfig) {
  const fs::path ini = copy_example_machine(dir_.path());
  std::ofstream(dir_.path() / "sim_mm.var", std::ios::trunc) << "5161 0\n5162 oops\n";
  expect_refused(ini, dir_.path(),
                 at(22) + "[RS274NGC] PARAMETER_FILE: " + (dir_.path() / "sim_mm.var").string() +
                     ":2: '5162 oops' is not a parameter line (NUMBER VALUE)");
}

TEST_F(StartChecksTest, ToolTableOfBareNumbersIsRefusedAtItsLine) {
  // LinuxCNC 2.4's table of bare numbers (pocket, length, diameter) is no table cncd reads: it
  // must not load as an empty table.
  const fs::path ini = copy_example_machine(dir_.path());
  std::ofstream(dir_.path() / "sim_mm.tbl", std::ios::trunc)
      << ";old table\n10 10 12.5 3.175\n11 11 20.0 6.35\n";
  expect_refused(ini, dir_.path(),
                 at(kToolTableLine) +
                     "[EMCIO] TOOL_TABLE: " + (dir_.path() / "sim_mm.tbl").string() +
                     ":2: '10' is not a tool table word (T P X Y Z A B C U V W D I J Q): is this "
                     "a tool table?");
  // Words of a tool line without its T.
  std::ofstream(dir_.path() / "sim_mm.tbl", std::ios::trunc) << "T1 P1 D6 Z0\nP2 D3 Z10\n";
  expect_refused(ini, dir_.path(),
                 (dir_.path() / "sim_mm.tbl").string() +
                     ":2: no T word: a tool line is 'T<number> P<pocket> ... ;comment'");
}

TEST_F(StartChecksTest, PositionFileTheDaemonRefusesIsRefusedByCheckConfig) {
  const fs::path ini = copy_example_machine(dir_.path());
  std::ofstream(dir_.path() / "sim_mm.position", std::ios::trunc) << "1\n2\nthree\n";
  expect_refused(ini, dir_.path(),
                 (dir_.path() / "sim_mm.position").string() + ":3: 'three' is not a position");
}

}  // namespace
}  // namespace cncd::test
