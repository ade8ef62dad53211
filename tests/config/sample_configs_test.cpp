// Every trivkins configuration LinuxCNC ships must load as LinuxCNC itself would load it.
#include <gtest/gtest.h>

#include "cncd/config/ini_file.hpp"
#include "cncd/config/machine_config.hpp"

namespace cncd::config::test {
namespace {

const std::filesystem::path kSamples = CNCD_LINUXCNC_SAMPLES_DIR;

std::vector<std::filesystem::path> trivkins_samples() {
  std::vector<std::filesystem::path> found;
  for (const auto& item : std::filesystem::recursive_directory_iterator(kSamples)) {
    if (!item.is_regular_file() || item.path().extension() != ".ini") continue;
    std::vector<Problem> problems;
    std::vector<Problem> warnings;
    const IniFile ini = IniFile::read(item.path(), problems, warnings);
    const auto kins = ini.value("KINS", "KINEMATICS");
    if (kins && (*kins == "trivkins" || kins->starts_with("trivkins "))) {
      found.push_back(item.path());
    }
  }
  std::sort(found.begin(), found.end());
  return found;
}

TEST(LinuxCncSampleConfigsTest, EveryTrivkinsSampleLoadsWithoutProblems) {
  if (!std::filesystem::is_directory(kSamples)) {
    GTEST_SKIP() << kSamples << " not found (package linuxcnc-uspace)";
  }
  const auto samples = trivkins_samples();
  EXPECT_GT(samples.size(), 100u);
  for (const auto& path : samples) {
    const auto result = load_machine_config(path);
    std::string problems;
    for (const auto& p : result.problems)
      problems += "\n  " + p.to_string();
    EXPECT_TRUE(result.ok()) << path << problems;
    if (result.ok()) {
      EXPECT_FALSE(describe(*result.config).empty());
    }
  }
}

TEST(LinuxCncSampleConfigsTest, EverySampleLoadsWithoutThrowing) {
  if (!std::filesystem::is_directory(kSamples)) {
    GTEST_SKIP() << kSamples << " not found (package linuxcnc-uspace)";
  }
  int loaded = 0;
  for (const auto& item : std::filesystem::recursive_directory_iterator(kSamples)) {
    if (!item.is_regular_file()) continue;
    const auto ext = item.path().extension();
    if (ext != ".ini" && ext != ".inc" && ext != ".hal" && ext != ".ngc") continue;
    EXPECT_NO_THROW(load_machine_config(item.path())) << item.path();
    ++loaded;
  }
  EXPECT_GT(loaded, 300);
}

}  // namespace
}  // namespace cncd::config::test
