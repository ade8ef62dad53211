#include "cncd/config/ini_file.hpp"

#include <gtest/gtest.h>

#include "temp_dir.hpp"

namespace cncd::config::test {
namespace {

class IniFileTest : public TempDirTest {
 protected:
  IniFile read(const std::string& name) {
    problems_.clear();
    warnings_.clear();
    return IniFile::read(dir_ / name, problems_, warnings_);
  }
  std::vector<int> warning_lines() const {
    std::vector<int> lines;
    for (const auto& warning : warnings_)
      lines.push_back(warning.line);
    return lines;
  }
  std::vector<Problem> problems_;
  std::vector<Problem> warnings_;
};

TEST_F(IniFileTest, ReadsSectionsKeysAndComments) {
  write("a.ini",
        "# comment\n; other comment\n[EMC]\n  MACHINE   =   My mill  \n\t; indented comment\n"
        "[TRAJ]\nCOORDINATES=X Y Z\nEMPTY =\n");
  const IniFile ini = read("a.ini");
  EXPECT_TRUE(problems_.empty()) << ::testing::PrintToString(strings(problems_));
  EXPECT_EQ(ini.value("EMC", "MACHINE"), "My mill");
  EXPECT_EQ(ini.value("TRAJ", "COORDINATES"), "X Y Z");
  EXPECT_EQ(ini.value("TRAJ", "EMPTY"), "");
  EXPECT_EQ(ini.find("EMC", "MACHINE")->source.line, 4);
  EXPECT_EQ(ini.entries().size(), 3u);
}

TEST_F(IniFileTest, NamesAreCaseSensitive) {
  write("a.ini", "[EMC]\nMACHINE = a\nmachine = b\n[emc]\nMACHINE = c\n");
  const IniFile ini = read("a.ini");
  EXPECT_EQ(ini.value("EMC", "MACHINE"), "a");
  EXPECT_EQ(ini.value("EMC", "machine"), "b");
  EXPECT_EQ(ini.value("emc", "MACHINE"), "c");
  EXPECT_FALSE(ini.value("Emc", "MACHINE").has_value());
}

TEST_F(IniFileTest, KeepsValuesVerbatimLikeLinuxCnc) {
  write("a.ini", "[A]\nK1 = 5 # not stripped\nK2 = [B]X\n[B]\nX = 7\n");
  const IniFile ini = read("a.ini");
  EXPECT_EQ(ini.value("A", "K1"), "5 # not stripped");
  EXPECT_EQ(ini.value("A", "K2"), "[B]X");
  const IniEntry* ref = ini.find_reference(*ini.value("A", "K2"));
  ASSERT_NE(ref, nullptr);
  EXPECT_EQ(ref->value, "7");
  EXPECT_EQ(ini.find_reference(" [B]X "), ref);
  EXPECT_EQ(ini.find_reference("[B]Y"), nullptr);
  EXPECT_EQ(ini.find_reference("B X"), nullptr);
}

TEST_F(IniFileTest, RepeatedKeysKeptInOrder) {
  write("a.ini", "[HAL]\nHALFILE = one.hal\nOTHER = x\nHALFILE = two.hal\nHALFILE = three.hal\n");
  const IniFile ini = read("a.ini");
  const auto all = ini.find_all("HAL", "HALFILE");
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0]->value, "one.hal");
  EXPECT_EQ(all[1]->value, "two.hal");
  EXPECT_EQ(all[2]->value, "three.hal");
  EXPECT_EQ(all[2]->source.line, 5);
  EXPECT_EQ(ini.find("HAL", "HALFILE", 2)->value, "two.hal");
  EXPECT_EQ(ini.find("HAL", "HALFILE", 4), nullptr);
}

TEST_F(IniFileTest, BackslashContinuesTheLine) {
  write("a.ini", "[APPLICATIONS]\nAPP = sim_pin \\\n  a.b \\\n  c.d\nNEXT = 1\r\n");
  const IniFile ini = read("a.ini");
  EXPECT_EQ(ini.value("APPLICATIONS", "APP"), "sim_pin   a.b   c.d");
  EXPECT_EQ(ini.find("APPLICATIONS", "APP")->source.line, 2);
  EXPECT_EQ(ini.find("APPLICATIONS", "NEXT")->source.line, 5);
  EXPECT_EQ(ini.value("APPLICATIONS", "NEXT"), "1");
}

TEST_F(IniFileTest, IncludesAreRelativeToTheIncludingFile) {
  write("main.ini", "[EMC]\nMACHINE = m\n#INCLUDE sub/traj.inc\n[KINS]\nJOINTS = 3\n");
  write("sub/traj.inc", "[TRAJ]\nCOORDINATES = XYZ\n#INCLUDE deeper/units.inc\n");
  write("sub/deeper/units.inc", "LINEAR_UNITS = mm\n");
  const IniFile ini = read("main.ini");
  EXPECT_TRUE(problems_.empty()) << ::testing::PrintToString(strings(problems_));
  EXPECT_EQ(ini.value("TRAJ", "COORDINATES"), "XYZ");
  const IniEntry* units = ini.find("TRAJ", "LINEAR_UNITS");
  ASSERT_NE(units, nullptr);
  EXPECT_EQ(units->source.file, (dir_ / "sub/deeper/units.inc").string());
  EXPECT_EQ(units->source.line, 1);
  EXPECT_EQ(ini.value("KINS", "JOINTS"), "3");
}

TEST_F(IniFileTest, IncludeLoopIsAProblemAtTheIncludeLine) {
  write("a.ini", "[A]\nX = 1\n#INCLUDE b.inc\n");
  write("b.inc", "Y = 2\n#INCLUDE a.ini\n");
  const IniFile ini = read("a.ini");
  ASSERT_EQ(problems_.size(), 1u) << ::testing::PrintToString(strings(problems_));
  EXPECT_EQ(problems_[0].to_string().rfind(at("b.inc", 2) + ": #INCLUDE: include loop", 0), 0u)
      << problems_[0].to_string();
  EXPECT_EQ(ini.value("A", "Y"), "2");
}

TEST_F(IniFileTest, IncludeDepthIsLimited) {
  for (int i = 0; i < 20; ++i) {
    write("f" + std::to_string(i) + ".inc", "#INCLUDE f" + std::to_string(i + 1) + ".inc\n");
  }
  write("f20.inc", "[A]\nDEEP = 1\n");
  read("f0.inc");
  ASSERT_EQ(problems_.size(), 1u) << ::testing::PrintToString(strings(problems_));
  EXPECT_NE(problems_[0].message.find("nested deeper than 16"), std::string::npos);
  EXPECT_EQ(problems_[0].file, (dir_ / "f16.inc").string());
}

TEST_F(IniFileTest, MissingIncludeIsAWarningAsInLinuxCnc) {
  write("a.ini", "[A]\n#INCLUDE\n#INCLUDE nosuchfile\nX = 1\n");
  const IniFile ini = read("a.ini");
  EXPECT_TRUE(problems_.empty());
  ASSERT_EQ(warning_lines(), (std::vector<int>{2, 3}));
  EXPECT_NE(warnings_[1].message.find("nosuchfile"), std::string::npos);
  EXPECT_EQ(ini.value("A", "X"), "1");
}

TEST_F(IniFileTest, OnlyTheFirstOfARepeatedSectionIsSeen) {
  write("a.ini", "[KINS]\nJOINTS = 3\n[OTHER]\n[KINS]\nJOINTS = 4\nEXTRA = 1\n");
  const IniFile ini = read("a.ini");
  EXPECT_EQ(ini.value("KINS", "JOINTS"), "3");
  EXPECT_FALSE(ini.value("KINS", "EXTRA").has_value());
  ASSERT_NE(ini.section("KINS", 1), nullptr);
  EXPECT_EQ(ini.section("KINS", 1)->source.line, 4);
  EXPECT_EQ(ini.entries().size(), 3u);
}

TEST_F(IniFileTest, HeaderMatchesAsAPrefixLikeLinuxCnc) {
  write("a.ini", "[EMCIO] section for IO is gone\nA = 1\n[B] # comment\nC = 2\n");
  const IniFile ini = read("a.ini");
  EXPECT_TRUE(problems_.empty());
  EXPECT_EQ(ini.value("EMCIO", "A"), "1");
  EXPECT_EQ(ini.value("B", "C"), "2");
  EXPECT_EQ(warning_lines(), std::vector<int>{1});
}

TEST_F(IniFileTest, StrayLinesAreWarnings) {
  write("a.ini", "[FILTER]\npy = python\nduh\n");
  const IniFile ini = read("a.ini");
  EXPECT_TRUE(problems_.empty());
  EXPECT_EQ(warning_lines(), std::vector<int>{3});
  EXPECT_EQ(ini.value("FILTER", "py"), "python");
}

TEST_F(IniFileTest, ListsUnusedEntries) {
  write("a.ini", "[A]\nX = 1\nY = 2\n");
  IniFile ini = read("a.ini");
  ini.mark_used(*ini.find("A", "X"));
  const auto unused = ini.unused_entries();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0]->key, "Y");
}

}  // namespace
}  // namespace cncd::config::test
