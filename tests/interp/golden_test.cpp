// Golden tests: each tests/golden/<case>/program.ngc must print exactly expected.canon (made
// with LinuxCNC's rs274) and fail with expected.error when that file exists.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include "rs274_session.hpp"

namespace cncd::interp::testing {
namespace {

std::vector<std::string> golden_cases() {
  std::vector<std::string> cases;
  for (const auto& entry : std::filesystem::directory_iterator(CNCD_GOLDEN_DIR)) {
    if (std::filesystem::exists(entry.path() / "program.ngc")) {
      cases.push_back(entry.path().filename().string());
    }
  }
  std::sort(cases.begin(), cases.end());
  return cases;
}

std::string case_name(const ::testing::TestParamInfo<std::string>& param) {
  std::string name = param.param;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, MatchesExpectedCanon) {
  const std::filesystem::path dir = std::filesystem::path(CNCD_GOLDEN_DIR) / GetParam();
  const auto program = dir / "program.ngc";
  const auto ours = run_ours(program, files_next_to(program));
  const std::string diff = line_diff(read_file(dir / "expected.canon"), ours.canon);
  EXPECT_TRUE(diff.empty()) << diff;
  const auto error_file = dir / "expected.error";
  const std::string expected_error =
      std::filesystem::exists(error_file) ? read_file(error_file) : std::string();
  std::string error = ours.error.empty() ? std::string() : ours.error + "\n";
  EXPECT_EQ(error, expected_error);
}

INSTANTIATE_TEST_SUITE_P(Cases, Golden, ::testing::ValuesIn(golden_cases()), case_name);

}  // namespace
}  // namespace cncd::interp::testing
