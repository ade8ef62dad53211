// Every trivkins configuration LinuxCNC ships must load as LinuxCNC itself would load it.
#include <gtest/gtest.h>

#include <map>
#include <string>

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

// Samples that cannot work in LinuxCNC either, with the one problem each must get.
const std::map<std::string, std::string> kBrokenSamples = {
    // HOME -4 below MIN_LIMIT -3: LinuxCNC stops with "Exceeded NEGATIVE soft limit" as
    // soon as the joint is homed.
    {"sim/gmoccapy/lathe_configs/lathe_imperial.ini",
     ":144: [JOINT_1] HOME: -4 is below MIN_LIMIT -3"},
    // JOINTS = 2 with [JOINT_0] and [JOINT_2]: LinuxCNC ignores [JOINT_2] and drives Z
    // (joint 1) with its defaults, 1 inch/s and no joint limits.
    {"sim/axis/panelui-demo/panelui-demo.ini",
     ":68: [KINS] JOINTS: JOINTS = 2, but joint 1 (axis Z) has no [JOINT_1] section"},
};

TEST(LinuxCncSampleConfigsTest, EveryTrivkinsSampleLoadsWithoutProblems) {
  if (!std::filesystem::is_directory(kSamples)) {
    GTEST_SKIP() << kSamples << " not found (package linuxcnc-uspace)";
  }
  const auto samples = trivkins_samples();
  EXPECT_GT(samples.size(), 100u);
  std::size_t broken = 0;
  for (const auto& path : samples) {
    const auto result = load_machine_config(path);
    std::string problems;
    for (const auto& p : result.problems)
      problems += "\n  " + p.to_string();
    const auto known = kBrokenSamples.find(path.lexically_relative(kSamples).string());
    if (known != kBrokenSamples.end()) {
      ++broken;
      ASSERT_EQ(result.problems.size(), 1u) << path << problems;
      EXPECT_NE(result.problems[0].to_string().find(known->second), std::string::npos)
          << path << problems;
      continue;
    }
    EXPECT_TRUE(result.ok()) << path << problems;
    if (result.ok()) {
      EXPECT_FALSE(describe(*result.config).empty());
    }
  }
  EXPECT_EQ(broken, kBrokenSamples.size());
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
