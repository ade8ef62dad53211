// Every declaration marked CNCD_RT (a function the servo period calls) is noexcept, and the
// servo period's entry points carry the mark. Reads the headers of motion and drivers.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = CNCD_SOURCE_DIR;

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The text without its // comments.
std::string code_of(const std::string& text) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto comment = line.find("//");
    out += line.substr(0, comment) + '\n';
  }
  return out;
}

std::vector<fs::path> headers() {
  std::vector<fs::path> out;
  for (const char* dir : {"motion/include/cncd/motion", "motion/src",
                          "drivers/include/cncd/drivers", "drivers/src"}) {
    for (const auto& entry : fs::directory_iterator(kSource / dir)) {
      if (entry.path().extension() == ".hpp") out.push_back(entry.path());
    }
  }
  return out;
}

// Each marked declaration, from the mark to its ';' or '{'.
std::vector<std::string> marked(const fs::path& path) {
  const std::string code = code_of(slurp(path));
  std::vector<std::string> out;
  for (auto at = code.find("CNCD_RT"); at != std::string::npos; at = code.find("CNCD_RT", at + 1)) {
    if (at >= 8 && code.compare(at - 8, 8, "#define ") == 0) continue;
    out.push_back(code.substr(at, code.find_first_of(";{", at) - at));
  }
  return out;
}

TEST(RtMarker, EveryMarkedDeclarationIsNoexcept) {
  int count = 0;
  for (const auto& path : headers()) {
    for (const auto& declaration : marked(path)) {
      ++count;
      EXPECT_NE(declaration.find("noexcept"), std::string::npos)
          << path.filename().string() << ": " << declaration;
    }
  }
  EXPECT_GT(count, 100);
}

TEST(RtMarker, TheServoPeriodAndTheDriversCallsAreMarked) {
  const auto has = [](const char* file, const char* declaration) {
    for (const auto& d : marked(kSource / file)) {
      if (d.find(declaration) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("motion/include/cncd/motion/servo_loop.hpp", "void cycle("));
  EXPECT_TRUE(has("motion/include/cncd/motion/path_executor.hpp", "Result advance("));
  EXPECT_TRUE(has("motion/include/cncd/motion/feedback_checks.hpp", "RtEvent& fault"));
  EXPECT_TRUE(has("motion/include/cncd/motion/spsc_ring.hpp", "bool push("));
  EXPECT_TRUE(has("drivers/include/cncd/drivers/seqlock.hpp", "void store("));
  EXPECT_TRUE(has("drivers/include/cncd/drivers/driver.hpp", "virtual void write("));
  EXPECT_TRUE(has("drivers/include/cncd/drivers/driver.hpp", "virtual void read("));
}

}  // namespace
