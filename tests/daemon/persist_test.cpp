#include "persist.hpp"

#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "daemon_process.hpp"
#include "server.hpp"

namespace cncd::daemon {
namespace {

namespace fs = std::filesystem;

class PersistTest : public ::testing::Test {
 protected:
  std::string read(const fs::path& p) { return test::slurp(p); }
  // Why a position file holding `content` is refused (for three joints).
  std::string corrupt_file_error(const std::string& content) {
    const auto file = dir_ / "position.txt";
    std::ofstream(file) << content;
    std::string error;
    EXPECT_FALSE(read_position_file(file, std::vector<JointRange>(3), error).has_value());
    return error;
  }
  test::TempDir temp_;
  const fs::path dir_ = temp_.path();
};

TEST_F(PersistTest, ReplacesTheFileAndLeavesNoTemporary) {
  const auto file = dir_ / "position.txt";
  ASSERT_EQ(atomic_write_file(file, "old\n"), "");
  ASSERT_EQ(atomic_write_file(file, "new\n"), "");
  EXPECT_EQ(read(file), "new\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_))
    ++entries;
  EXPECT_EQ(entries, 1);
}

TEST_F(PersistTest, FailureKeepsTheOldFileAndNamesIt) {
  const auto sub = dir_ / "ro";
  fs::create_directories(sub);
  const auto file = sub / "position.txt";
  ASSERT_EQ(atomic_write_file(file, "1.0\n"), "");
  // A directory in the way of the rename makes the replacement fail.
  const auto blocked = sub / "blocked";
  fs::create_directories(blocked / "inside");
  const std::string error = atomic_write_file(blocked, "x");
  EXPECT_NE(error.find("blocked"), std::string::npos) << error;
  EXPECT_EQ(read(file), "1.0\n");
}

TEST_F(PersistTest, PositionFileRoundTrips) {
  const auto file = dir_ / "position.txt";
  ASSERT_EQ(atomic_write_file(file, format_position_file({1.5, -2.25, 3})), "");
  std::string error;
  const auto joints = read_position_file(file, std::vector<JointRange>(3), error);
  ASSERT_TRUE(joints.has_value()) << error;
  EXPECT_EQ(*joints, (std::vector<double>{1.5, -2.25, 3}));
}

TEST_F(PersistTest, MissingPositionFileIsNotAnError) {
  std::string error;
  const auto joints = read_position_file(dir_ / "none.txt", std::vector<JointRange>(3), error);
  ASSERT_TRUE(joints.has_value());
  EXPECT_TRUE(joints->empty());
}

TEST_F(PersistTest, CorruptPositionFileNamesFileAndLine) {
  const std::string error = corrupt_file_error("1.0\nbanana\n3.0\n");
  EXPECT_NE(error.find("position.txt:2"), std::string::npos) << error;
}

TEST_F(PersistTest, EmptyOrShortPositionFileIsCorrupt) {
  const std::string error = corrupt_file_error("");
  EXPECT_NE(error.find("0 positions"), std::string::npos) << error;
}

TEST_F(PersistTest, PositionsThatAreNotFiniteOrFarOutsideTheLimitsAreNeverWritten) {
  const auto file = dir_ / "position.txt";
  const std::vector<JointRange> ranges{{-10, 300}, {-10, 200}, {-100, 50}};
  ASSERT_EQ(write_position_file(file, {1, 2, 3}, ranges), "");
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL, 1e300, -116.0}) {
    SCOPED_TRACE(bad);
    const std::string error = write_position_file(file, {1, 2, bad}, ranges);
    EXPECT_NE(error.find("position.txt: not written"), std::string::npos) << error;
    EXPECT_NE(error.find("joint 2 position"), std::string::npos) << error;
    EXPECT_EQ(read(file), "1.000000000\n2.000000000\n3.000000000\n");
  }
  // 10 % of the travel past a limit is still a place an unhomed machine may stand.
  EXPECT_EQ(write_position_file(file, {330, -30, -115}, ranges), "");
  std::string error;
  const auto joints = read_position_file(file, ranges, error);
  ASSERT_TRUE(joints.has_value()) << error;
  EXPECT_EQ((*joints)[2], -115);
}

TEST_F(PersistTest, ReadingRefusesPositionsFarOutsideTheLimitsWithFileLineAndLimits) {
  const auto file = dir_ / "position.txt";
  std::ofstream(file) << "0\n\n500\n0\n";
  std::string error;
  EXPECT_FALSE(read_position_file(file, {{-10, 300}, {-10, 200}, {-100, 50}}, error));
  EXPECT_NE(error.find("position.txt:3: joint 1 position 500 is outside its limits [-10, 200] "
                       "by more than 10 % of its travel"),
            std::string::npos)
      << error;
}

TEST(MergeDiff, KeepsOnlyChangedLeaves) {
  const nlohmann::json before = {{"a", 1}, {"b", {{"c", 2}, {"d", 3}}}, {"e", {1, 2}}};
  const nlohmann::json after = {{"a", 1}, {"b", {{"c", 2}, {"d", 4}}}, {"e", {1, 3}}};
  EXPECT_EQ(merge_diff(before, after), (nlohmann::json{{"b", {{"d", 4}}}, {"e", {1, 3}}}));
  EXPECT_TRUE(merge_diff(after, after).empty());
}

}  // namespace
}  // namespace cncd::daemon
