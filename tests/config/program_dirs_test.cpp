// [DISPLAY] PROGRAM_PREFIX and [CNCD] PROGRAM_DIRS: the directories program.open opens
// programs from.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

namespace fs = std::filesystem;

class ProgramDirsTest : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fake_env() = {{"HOME", (dir_ / "home").string()}, {"XDG_STATE_HOME", dir_.string()}};
    fs::create_directories(dir_ / "conf/nc");
    fs::create_directories(dir_ / "home/nc_files");
    fs::create_directories(dir_ / "shared");
  }

  LoadResult load(const std::string& display, const std::string& cncd) {
    LoadOptions options;
    options.getenv = fake_getenv;
    return load_machine_config(
        write("conf/mill.ini", minimal_ini() + "[DISPLAY]\n" + display + "[CNCD]\n" + cncd),
        options);
  }
};

TEST_F(ProgramDirsTest, NeitherKeyMeansTheIniDirectory) {
  const auto result = load("", "");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.config->program_dirs, std::vector<fs::path>{dir_ / "conf"});
  EXPECT_FALSE(any_contains(result.warnings, "PROGRAM_"))
      << ::testing::PrintToString(strings(result.warnings));
  EXPECT_NE(describe(*result.config).find("Programs in:  " + (dir_ / "conf").string()),
            std::string::npos);
}

TEST_F(ProgramDirsTest, PrefixAndListAreRelativeToTheIniWithTildeForHome) {
  const auto result =
      load("PROGRAM_PREFIX = nc/\n",
           "PROGRAM_DIRS = ~/nc_files: " + (dir_ / "shared").string() + " :../conf\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  const std::vector<fs::path> expected = {dir_ / "conf/nc", dir_ / "home/nc_files", dir_ / "shared",
                                          dir_ / "conf"};
  EXPECT_EQ(result.config->program_dirs, expected);
  EXPECT_FALSE(any_contains(result.warnings, "PROGRAM_"))
      << ::testing::PrintToString(strings(result.warnings));
}

TEST_F(ProgramDirsTest, AMissingDirectoryIsAWarning) {
  fake_env().erase("HOME");
  const auto result = load("PROGRAM_PREFIX = ~/nc_files\n", "PROGRAM_DIRS = nowhere\n");
  ASSERT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
  // Without $HOME the prefix is left out; the directory not there yet stays in the list.
  EXPECT_EQ(result.config->program_dirs, std::vector<fs::path>{dir_ / "conf/nowhere"});
  EXPECT_TRUE(any_contains(result.warnings,
                           "[DISPLAY] PROGRAM_PREFIX: '~/nc_files': $HOME is "
                           "not set"))
      << ::testing::PrintToString(strings(result.warnings));
  EXPECT_TRUE(any_contains(
      result.warnings,
      "[CNCD] PROGRAM_DIRS: '" + (dir_ / "conf/nowhere").string() + "' is not a directory (yet)"))
      << ::testing::PrintToString(strings(result.warnings));
}

}  // namespace
}  // namespace cncd::config::test
