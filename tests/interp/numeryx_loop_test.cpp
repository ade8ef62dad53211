// Numeryx for/next loops that would never end and next lines that close a loop they do not
// own: refused at their line. The programs are read with a bounded number of blocks, so that a
// loop that never ends fails the test instead of hanging it.
#include <gtest/gtest.h>

#include <string>

#include "cncd/interp/interpreter.hpp"

namespace cncd::interp {
namespace {

class CountingSink final : public CanonSink {
 public:
  void emit(const CanonCommand&) override { ++commands; }
  long commands = 0;
};

// The error the program ends with, "ended" when it ends, or "still running" after `blocks`.
std::string outcome(const std::string& program, int blocks = 100000) {
  Interpreter interp;
  if (auto error = interp.open_string("(dialect numeryx)\n" + program, "nx.ngc"))
    return error->to_string();
  CountingSink sink;
  for (int i = 0; i < blocks; ++i) {
    switch (interp.step(sink)) {
      case Interpreter::Step::block:
        break;
      case Interpreter::Step::end:
        return "ended";
      case Interpreter::Step::error:
        return interp.error() ? interp.error()->to_string() : "error without a message";
    }
  }
  return "still running after " + std::to_string(blocks) + " blocks";
}

TEST(NumeryxLoop, AStepLostInTheRoundingOfTheStartIsRefusedAtTheForLine) {
  // 1e20 + 1 is 1e20 in a double: #1 would never move.
  EXPECT_EQ(outcome("for #1=100000000000000000000 to 200000000000000000000\ng x1\nnext\nm30\n"),
            "nx.ngc:2:1: Step 1 does not change #1 (1e+20): the for loop would never reach "
            "2e+20");
  EXPECT_EQ(outcome("for #1=1 to 2 step 0.00000000000000001\ng x1\nnext #1\nm30\n"),
            "nx.ngc:2:1: Step 1.0000000000000001e-17 does not change #1 (1): the for loop would "
            "never reach 2");
  // The same numbers in a loop that runs no pass are no loop at all.
  EXPECT_EQ(outcome("for #1=3 to 2 step 0.00000000000000001\ng x1\nnext #1\nm30\n"), "ended");
}

TEST(NumeryxLoop, ABodyThatPutsTheVariableOutOfTheStepsReachIsRefusedAtNext) {
  EXPECT_EQ(outcome("for #1=0 to 300000000000000000000\n#1=100000000000000000000\nnext #1\nm30\n"),
            "nx.ngc:4:1: Step 1 does not change #1 (1e+20): the for loop would never reach "
            "3e+20");
}

TEST(NumeryxLoop, LoopsThatProgressStillRun) {
  EXPECT_EQ(outcome("for #1=0 to 1 step 0.001\ng x=#1\nnext #1\nm30\n"), "ended");
  EXPECT_EQ(outcome("for #1=3 to -3 step -1.5\ng x=#1\nnext\nm30\n"), "ended");
}

TEST(NumeryxLoop, NextInASubroutineCannotCloseTheCallersFor) {
  const std::string program =
      "o100 sub\n"
      "g x1\n"
      "next #1\n"
      "o100 endsub\n"
      "for #1=0 to 2\n"
      "o100 call\n"
      "next #1\n"
      "m30\n";
  EXPECT_EQ(outcome(program),
            "nx.ngc:4:1: next without for in subroutine o100: the for #1 of line 6 belongs to "
            "its caller");
  // Without a number, likewise.
  std::string bare = program;
  bare.replace(bare.find("next #1\n"), 8, "next\n");
  EXPECT_EQ(outcome(bare),
            "nx.ngc:4:1: next without for in subroutine o100: the for #1 of line 6 belongs to "
            "its caller");
}

TEST(NumeryxLoop, ASubroutinesOwnLoopRunsAndMustCloseBeforeItEnds) {
  EXPECT_EQ(outcome("o100 sub\nfor #2=0 to 2\ng x=#2\nnext #2\no100 endsub\n"
                    "for #1=0 to 1\no100 call\nnext #1\nm30\n"),
            "ended");
  EXPECT_EQ(outcome("o100 sub\nfor #2=0 to 2\ng x=#2\no100 endsub\no100 call\nm30\n"),
            "nx.ngc:5: for #2 of line 3 has no next before the end of subroutine o100");
}

}  // namespace
}  // namespace cncd::interp
