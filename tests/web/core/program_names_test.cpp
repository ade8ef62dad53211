// Program names and URL segments: what may reach the program directory at all.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cncd/web/program_dir.hpp"

namespace cncd::web {
namespace {

TEST(ProgramNameTest, PlainNamesWithAnyExtensionPass) {
  for (const std::string& name :
       std::vector<std::string>{"part.ngc", "a", "G81 drill.nc", "x..y", "x.", "tap~1.TAP",
                                "\xc3\xa9tau.ngc", std::string(255, 'n')}) {
    EXPECT_EQ(check_program_name(name), "") << name;
  }
}

TEST(ProgramNameTest, AnythingButOnePlainComponentIsRefusedWithTheReason) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"", "the name is empty"},
      {".", "'.' is not a file name"},
      {"..", "'..' is not a file name"},
      {"../x", "the name contains '/': it must be one file name, without directories"},
      {"/etc/passwd", "the name contains '/': it must be one file name, without directories"},
      {"a/", "the name contains '/': it must be one file name, without directories"},
      {std::string("a\0b", 3), "the name contains a NUL character"},
      {"a\nb", "the name contains a control character"},
      {"a\tb", "the name contains a control character"},
      {"a\x7f", "the name contains a control character"},
      {".hidden", "the name starts with '.' (hidden files are not programs)"},
      {".cncd-upload-0123", "the name starts with '.' (hidden files are not programs)"},
      {std::string(256, 'n'), "the name is 256 bytes long; at most 255 are allowed"},
  };
  for (const auto& [name, why] : cases)
    EXPECT_EQ(check_program_name(name), why) << name;
}

TEST(PercentDecodeTest, DecodesEscapesAndKeepsEverythingElse) {
  EXPECT_EQ(percent_decode("part%20one.ngc").text, "part one.ngc");
  EXPECT_EQ(percent_decode("a+b").text, "a+b");
  EXPECT_EQ(percent_decode("%C3%a9").text, "\xc3\xa9");
  EXPECT_EQ(percent_decode("").text, "");
  EXPECT_TRUE(percent_decode("plain").ok());
}

TEST(PercentDecodeTest, EncodedTraversalDecodesToWhatTheNameCheckRefuses) {
  for (const std::string segment : {"%2e%2e%2fx", "%2E%2E%2Fx", "..%2fx", "%2fetc%2fpasswd",
                                    "%2e%2e", "%2e", "%2ehidden", "a%0ab"}) {
    const Decoded d = percent_decode(segment);
    ASSERT_TRUE(d.ok()) << segment;
    EXPECT_NE(check_program_name(d.text), "") << segment << " -> " << d.text;
  }
  EXPECT_EQ(percent_decode("%2e%2e%2fx").text, "../x");
}

TEST(PercentDecodeTest, MalformedEscapesAndNulAreRefused) {
  for (const std::string bad : {"%", "a%", "%2", "a%2", "%zz", "%g0", "%0g", "%%41"}) {
    const Decoded d = percent_decode(bad);
    EXPECT_EQ(d.error, "a '%' not followed by two hex digits") << bad;
    EXPECT_EQ(d.text, "") << bad;
  }
  EXPECT_EQ(percent_decode("a%00b").error, "%00 (a NUL character)");
}

}  // namespace
}  // namespace cncd::web
