// Fanuc-style subprograms (M98/M99) where cncd departs from LinuxCNC's rs274 on purpose, and
// the errors whose text names the program file (which a golden case cannot hold).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "probe_support.hpp"

namespace cncd::interp {
namespace {

struct Outcome {
  std::string error;
  std::vector<StraightTraverse> traverses;
};

Outcome run(const std::string& text, std::filesystem::path* file = nullptr) {
  TempDir dir;
  const auto program = dir.write("fanuc.ngc", text);
  if (file) *file = program;
  Interpreter interp(InterpOptions{});
  Recorder recorder;
  std::string error;
  if (auto opened = interp.open(program)) {
    error = opened->to_string();
  } else {
    error = run_answering(interp, recorder, {});
  }
  return {error, recorder.all<StraightTraverse>()};
}

// rs274 silently drops the other words of an M98 line (M98 P100 G0 X1 never moves to X1);
// cncd refuses the line instead of skipping a move the program asks for.
TEST(FanucSubprograms, OtherWordsOnAnM98LineAreRefused) {
  const auto moved = run("M98 P100 G0 X1\nM2\nO100\nG0 Y1\nM99\n");
  EXPECT_NE(moved.error.find(":1: An M98 line takes only P and L words"), std::string::npos)
      << moved.error;
  EXPECT_TRUE(moved.traverses.empty());
  EXPECT_NE(run("M98 P100 M3 S100\nM2\nO100\nM99\n").error.find("only P and L"), std::string::npos);
  EXPECT_EQ(run("N10 M98 P100 L2 (comment)\nM2\nO100\nG0 Y1\nM99\n").error, "");
}

// rs274 stops with "Bug: Reached convert_stop() from M99 as subprogram return".
TEST(FanucSubprograms, AnM99EndingASubprogramMustBeAlone) {
  const auto out = run("M98 P100\nM2\nO100\nG0 Y1 M99\n");
  EXPECT_NE(out.error.find(":4: An M99 that ends a subprogram must be alone"), std::string::npos)
      << out.error;
}

// rs274 evaluates an M98 line's words in the subprogram's scope (a local #<n> of the caller is
// "not defined" there) and loses the caller's locals after M98 .. L0; cncd keeps the caller's.
TEST(FanucSubprograms, TheCallersLocalParametersStayVisible) {
  const auto out = run("#<n> = 100\nM98 P#<n> L0\nM98 P#<n>\nG0 X#<n>\nM2\nO100\nG0 Y1\nM99\n");
  EXPECT_EQ(out.error, "");
  ASSERT_EQ(out.traverses.size(), 2U);
  EXPECT_DOUBLE_EQ(out.traverses[0].end[1], 1.0);
  EXPECT_DOUBLE_EQ(out.traverses[1].end[0], 100.0);
}

TEST(FanucSubprograms, AMissingSubprogramIsSoughtToTheEndOfTheFile) {
  std::filesystem::path file;
  const auto out = run("G0 X1\nM98 P300\nM2\nO100\nM99\n", &file);
  EXPECT_NE(out.error.find("EOF in file:" + file.string() + " seeking o-word: o<300> from line: 2"),
            std::string::npos)
      << out.error;
}

// A subprogram repeated L times that never moves still ends: L is finite, and a nesting of
// M98 calls ten deep is refused as rs274 refuses it.
TEST(FanucSubprograms, RepeatsAndNestingAreBounded) {
  const auto repeated = run("M98 P1 L300\nG0 X#2\nM2\nO1\n#2 = [#2 + 1]\nM99\n");
  EXPECT_EQ(repeated.error, "");
  ASSERT_EQ(repeated.traverses.size(), 1U);
  EXPECT_DOUBLE_EQ(repeated.traverses[0].end[0], 300.0);
  const auto deep = run("M98 P1\nM2\nO1\nG91 G0 X1\nM98 P1\nM99\n");
  EXPECT_NE(deep.error.find(":5: Too many subroutine levels"), std::string::npos) << deep.error;
  EXPECT_EQ(deep.traverses.size(), 9U);
}

TEST(FanucSubprograms, TheNumeryxDialectRefusesThem) {
  EXPECT_NE(run("(dialect numeryx)\nM98 P1\nM2\n")
                .error.find("M98 is not supported in the "
                            "Numeryx dialect"),
            std::string::npos);
}

}  // namespace
}  // namespace cncd::interp
