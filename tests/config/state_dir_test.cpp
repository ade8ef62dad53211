// Where the parameter, tool and position files live: the state directory and its seeds.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

class StateDirTest : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fake_env() = {{"HOME", "/home/op"}};
  }

  LoadResult load(const std::string& cncd_section, const std::string& state_files,
                  const std::filesystem::path& state_dir = {}) {
    LoadOptions options;
    options.getenv = fake_getenv;
    options.state_dir = state_dir;
    // POSITION_FILE goes into the [TRAJ] section the minimal machine already has.
    std::string ini = minimal_ini();
    std::string files = state_files;
    if (const auto at = files.find(kPositionLine); at != std::string::npos) {
      files.erase(at, std::string(kPositionLine).size());
      ini.replace(ini.find("[TRAJ]\n"), 7, std::string("[TRAJ]\n") + kPositionLine);
    }
    return load_machine_config(write("conf/mill.ini", ini + files + "[CNCD]\n" + cncd_section),
                               options);
  }

  static constexpr const char* kPositionLine = "POSITION_FILE = mill.position\n";
  static constexpr const char* kFiles =
      "[RS274NGC]\nPARAMETER_FILE = mill.var\n[EMCIO]\nTOOL_TABLE = tools/mill.tbl\n"
      "POSITION_FILE = mill.position\n";
};

TEST_F(StateDirTest, RelativeStateFilesLiveInTheStateDirectorySeededFromBesideTheIni) {
  fake_env()["XDG_STATE_HOME"] = "/home/op/.state";
  const auto result = load("", kFiles);
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const auto& c = *result.config;
  const std::filesystem::path state = "/home/op/.state/cncd/mill";
  EXPECT_EQ(c.cncd.state_dir, state);
  EXPECT_EQ(c.cncd.state_dir_origin, "$XDG_STATE_HOME/cncd/mill");
  EXPECT_EQ(c.parameter_file, state / "mill.var");
  EXPECT_EQ(c.tool_table, state / "tools/mill.tbl");
  EXPECT_EQ(c.position_file, state / "mill.position");
  EXPECT_EQ(c.parameter_file_seed, dir_ / "conf/mill.var");
  EXPECT_EQ(c.tool_table_seed, dir_ / "conf/tools/mill.tbl");
  EXPECT_EQ(c.position_file_seed, dir_ / "conf/mill.position");
  EXPECT_NE(describe(c).find(state.string()), std::string::npos) << describe(c);
}

TEST_F(StateDirTest, TheDirectoryIsChosenInTheDocumentedOrder) {
  // Without XDG_STATE_HOME: the XDG default under $HOME.
  auto result = load("", kFiles);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.config->cncd.state_dir, "/home/op/.local/state/cncd/mill");
  // systemd's StateDirectory= (the first of several) comes before XDG.
  fake_env()["XDG_STATE_HOME"] = "/home/op/.state";
  fake_env()["STATE_DIRECTORY"] = "/var/lib/cncd:/var/lib/other";
  result = load("", kFiles);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.config->cncd.state_dir, "/var/lib/cncd");
  EXPECT_EQ(result.config->parameter_file, "/var/lib/cncd/mill.var");
  // The INI's STATE_DIR (relative to the INI) before the environment.
  result = load("STATE_DIR = ../state\n", kFiles);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.config->cncd.state_dir, dir_ / "state");
  EXPECT_EQ(result.config->cncd.state_dir_origin, "[CNCD] STATE_DIR");
  // --state-dir before all of them.
  result = load("STATE_DIR = ../state\n", kFiles, dir_ / "cli");
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.config->cncd.state_dir, dir_ / "cli");
  EXPECT_EQ(result.config->tool_table, dir_ / "cli/tools/mill.tbl");
}

// [CNCD] PROBE_DIR: by default probe/ in the state directory, a relative one in it too.
TEST_F(StateDirTest, ProbeFilesGoToTheStateDirectorysProbeDirectory) {
  const std::filesystem::path state = "/srv/cnc/state";
  auto probe_dir = [&](const std::string& cncd) {
    const auto result = load("STATE_DIR = " + state.string() + "\n" + cncd, kFiles);
    EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
    return result.ok() ? result.config->cncd.probe_dir : std::filesystem::path();
  };
  EXPECT_EQ(probe_dir(""), state / "probe");
  EXPECT_EQ(probe_dir("PROBE_DIR = results\n"), state / "results");
  EXPECT_EQ(probe_dir("PROBE_DIR = /srv/cnc/probes\n"), "/srv/cnc/probes");
}

TEST_F(StateDirTest, AbsoluteStateFilesAreUsedWhereTheyAreWithoutASeed) {
  const auto result = load("", "[RS274NGC]\nPARAMETER_FILE = /srv/mill/params.var\n");
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.config->parameter_file, "/srv/mill/params.var");
  EXPECT_TRUE(result.config->parameter_file_seed.empty());
  EXPECT_TRUE(result.config->tool_table.empty());
}

TEST_F(StateDirTest, ARelativeStateFileWithNoStateDirectoryToBeFoundIsAProblem) {
  fake_env().clear();
  auto result = load("", kFiles);
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(any_contains(result.problems,
                           "[RS274NGC] PARAMETER_FILE: a relative path needs "
                           "a state directory: set [CNCD] STATE_DIR"))
      << ::testing::PrintToString(strings(result.problems));
  // Without state files nothing needs one.
  result = load("", "");
  EXPECT_TRUE(result.ok());
}

TEST_F(StateDirTest, TheCopyToReadIsTheStateFileElseItsSeed) {
  const auto file = dir_ / "state/mill.var";
  const auto seed = write("conf/mill.var", "5221 1\n");
  EXPECT_EQ(state_file_to_read(file, seed), seed);
  EXPECT_EQ(state_file_to_read(file, dir_ / "conf/none.var"), file);
  EXPECT_EQ(state_file_to_read(file, {}), file);
  write("state/mill.var", "5221 2\n");
  EXPECT_EQ(state_file_to_read(file, seed), file);
}

}  // namespace
}  // namespace cncd::config::test
