// Differential test against LinuxCNC's own interpreter: every golden program and every program
// in tests/interp/programs is run through /usr/bin/rs274 and through ours; outputs must agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rs274_session.hpp"

namespace cncd::interp::testing {
namespace {

constexpr const char* kLinuxCncSamples = "/usr/share/doc/linuxcnc/examples/nc_files";

std::vector<std::string> programs() {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(CNCD_GOLDEN_DIR)) {
    const auto program = entry.path() / "program.ngc";
    if (std::filesystem::exists(program)) found.push_back(program.string());
  }
  if (std::filesystem::exists(CNCD_EXTRA_PROGRAMS_DIR)) {
    for (const auto& entry :
         std::filesystem::recursive_directory_iterator(CNCD_EXTRA_PROGRAMS_DIR)) {
      if (entry.path().extension() == ".ngc") found.push_back(entry.path().string());
    }
  }
  // LinuxCNC's own sample programs, when installed.
  std::ifstream list(CNCD_SAMPLES_LIST);
  std::string name;
  while (std::getline(list, name)) {
    if (name.empty() || name[0] == '#') continue;
    const auto path = std::filesystem::path(kLinuxCncSamples) / name;
    if (std::filesystem::exists(path)) found.push_back(path.string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::string case_name(const ::testing::TestParamInfo<std::string>& param) {
  const std::filesystem::path path = param.param;
  std::string name = path.parent_path().filename().string() + "_" + path.stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

class AgainstRs274 : public ::testing::TestWithParam<std::string> {};

TEST_P(AgainstRs274, SameOutput) {
  const std::filesystem::path program = GetParam();
  const auto files = files_next_to(program);
  const auto theirs = run_rs274(program, files);
  if (!theirs) GTEST_SKIP() << kRs274 << " is not installed";
  const auto ours = run_ours(program, files);
  const std::string diff = line_diff(theirs->canon, ours.canon);
  EXPECT_TRUE(diff.empty()) << diff;
  EXPECT_EQ(ours.error, theirs->error);
}

INSTANTIATE_TEST_SUITE_P(Programs, AgainstRs274, ::testing::ValuesIn(programs()), case_name);

}  // namespace
}  // namespace cncd::interp::testing
