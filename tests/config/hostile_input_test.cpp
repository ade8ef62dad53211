// Bad bytes and broken structure must give clear problems, never a crash, hang or exception.
#include <gtest/gtest.h>

#include <random>

#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

using HostileInputTest = TempDirTest;

TEST_F(HostileInputTest, MissingFile) {
  const auto result = load_machine_config(dir_ / "nope.ini");
  EXPECT_FALSE(result.ok());
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.problems[0].to_string().rfind((dir_ / "nope.ini").string() + ": cannot open", 0),
            0u)
      << result.problems[0].to_string();
}

TEST_F(HostileInputTest, DirectoryInsteadOfFile) {
  const auto result = load_machine_config(dir_);
  EXPECT_FALSE(result.ok());
  EXPECT_TRUE(any_contains(result.problems, "is a directory"));
}

TEST_F(HostileInputTest, EmptyFile) {
  const auto result = load_machine_config(write("empty.ini", ""));
  EXPECT_FALSE(result.ok());
  EXPECT_TRUE(any_contains(result.problems, "no sections"));
}

TEST_F(HostileInputTest, BinaryJunk) {
  std::mt19937 random(42);
  std::string junk(200000, '\0');
  for (char& c : junk)
    c = static_cast<char>(random() & 0xff);
  const auto result = load_machine_config(write("junk.ini", junk));
  EXPECT_FALSE(result.ok());
  EXPECT_TRUE(any_contains(result.problems, "is this a text file?"));
  EXPECT_TRUE(any_contains(result.problems, "stopped reading this file"));
  EXPECT_LT(result.problems.size(), 30u);
}

TEST_F(HostileInputTest, TenMegabyteLine) {
  const std::string ini = minimal_ini() + "[DISPLAY]\nGARBAGE = " + std::string(10'000'000, 'x') +
                          "\nMAX_FEED_OVERRIDE = 1.2\n";
  const auto result = load_machine_config(write("long.ini", ini));
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  const int line =
      1 + static_cast<int>(std::count(ini.begin(), ini.begin() + ini.find("GARBAGE"), '\n'));
  EXPECT_EQ(result.problems[0].to_string(),
            at("long.ini", line) + ": line longer than 4096 bytes; ignored");
}

TEST_F(HostileInputTest, FileTooLarge) {
  const auto result =
      load_machine_config(write("huge.ini", "[A]\n" + std::string(17u * 1024u * 1024u, '#')));
  EXPECT_FALSE(result.ok());
  EXPECT_TRUE(any_contains(result.problems, "file is too large"));
}

TEST_F(HostileInputTest, NulByteReportsItsLine) {
  std::string ini = minimal_ini();
  ini.insert(ini.find("MACHINE = test") + 10, std::string("\0", 1));
  const auto result = load_machine_config(write("nul.ini", ini));
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.problems[0].to_string(),
            at("nul.ini", 2) + ": line contains a NUL byte; is this a text file?");
}

TEST_F(HostileInputTest, SectionWithoutName) {
  const auto result = load_machine_config(write("a.ini", minimal_ini() + "[]\nX = 1\n"));
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.problems[0].to_string(), at("a.ini", 42) + ": section header '[]' has no name");
}

TEST_F(HostileInputTest, UnterminatedSection) {
  const auto result = load_machine_config(write("a.ini", minimal_ini() + "[DISPLAY\nX = 1\n"));
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.problems[0].to_string(),
            at("a.ini", 42) + ": unterminated section header '[DISPLAY' (missing ']')");
}

TEST_F(HostileInputTest, NonFiniteNumbers) {
  std::string ini = minimal_ini();
  ini.replace(ini.find("MAX_VELOCITY = 50"), 17, "MAX_VELOCITY = nan");
  ini.replace(ini.find("MAX_LIMIT = 100"), 15, "MAX_LIMIT = inf");
  ini.replace(ini.find("MAX_ACCELERATION = 500"), 22, "MAX_ACCELERATION = 1e999");
  const auto result = load_machine_config(write("a.ini", ini));
  const auto text = strings(result.problems);
  ASSERT_EQ(text.size(), 3u) << ::testing::PrintToString(text);
  EXPECT_EQ(text[0], at("a.ini", 14) + ": [AXIS_X] MAX_LIMIT: 'inf' is not a finite number");
  EXPECT_EQ(text[1], at("a.ini", 15) + ": [AXIS_X] MAX_VELOCITY: 'nan' is not a finite number");
  EXPECT_EQ(text[2], at("a.ini", 16) +
                         ": [AXIS_X] MAX_ACCELERATION: '1e999' is too large or too small a number");
}

TEST_F(HostileInputTest, IncludeLoopThroughLoader) {
  write("b.inc", "#INCLUDE a.ini\n");
  const auto result = load_machine_config(write("a.ini", "#INCLUDE b.inc\n" + minimal_ini()));
  ASSERT_EQ(result.problems.size(), 1u) << ::testing::PrintToString(strings(result.problems));
  EXPECT_EQ(result.problems[0].line, 1);
  EXPECT_NE(result.problems[0].message.find("include loop"), std::string::npos);
}

}  // namespace
}  // namespace cncd::config::test
