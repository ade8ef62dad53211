// The G81 examples of the canned-cycle documentation, checked move by move.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

class MoveRecorder final : public CanonSink {
 public:
  void emit(const CanonCommand& command) override {
    if (std::holds_alternative<StraightTraverse>(command.op) ||
        std::holds_alternative<StraightFeed>(command.op)) {
      moves.push_back(format_rs274(command, 3));
    }
    all.push_back(format_rs274(command));
  }
  std::vector<std::string> moves;
  std::vector<std::string> all;
};

std::vector<std::string> run_moves(const std::string& program) {
  Interpreter interp;
  EXPECT_FALSE(interp.open_string(program, "seed.ngc"));
  MoveRecorder recorder;
  const auto error = run_program(interp, recorder);
  EXPECT_FALSE(error) << (error ? error->to_string() : "");
  return recorder.moves;
}

TEST(SeedExamples, AbsoluteG81FromOneTwoThree) {
  const auto moves = run_moves("G0 X1 Y2 Z3\nF100\nG90 G81 G98 X4 Y5 Z1.5 R2.8\nM2\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000)",  // positioning before the cycle
      "STRAIGHT_TRAVERSE(4.0000, 5.0000, 3.0000)",  // 1. parallel to XY
      "STRAIGHT_TRAVERSE(4.0000, 5.0000, 2.8000)",  // 2. down to R
      "STRAIGHT_FEED(4.0000, 5.0000, 1.5000)",      // 3. feed to Z
      "STRAIGHT_TRAVERSE(4.0000, 5.0000, 3.0000)",  // 4. back to old Z
  };
  EXPECT_EQ(moves, expected);
}

TEST(SeedExamples, IncrementalG81WithThreeRepeats) {
  const auto moves = run_moves("G0 X1 Y2 Z3\nF100\nG91 G81 G98 X4 Y5 Z-0.6 R1.8 L3\nM2\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000)",   "STRAIGHT_TRAVERSE(1.0000, 2.0000, 4.8000)",
      "STRAIGHT_TRAVERSE(5.0000, 7.0000, 4.8000)",   "STRAIGHT_FEED(5.0000, 7.0000, 4.2000)",
      "STRAIGHT_TRAVERSE(5.0000, 7.0000, 4.8000)",   "STRAIGHT_TRAVERSE(9.0000, 12.0000, 4.8000)",
      "STRAIGHT_FEED(9.0000, 12.0000, 4.2000)",      "STRAIGHT_TRAVERSE(9.0000, 12.0000, 4.8000)",
      "STRAIGHT_TRAVERSE(13.0000, 17.0000, 4.8000)", "STRAIGHT_FEED(13.0000, 17.0000, 4.2000)",
      "STRAIGHT_TRAVERSE(13.0000, 17.0000, 4.8000)",
  };
  EXPECT_EQ(moves, expected);
}

TEST(SeedExamples, StartingPositionComesFromSetPosition) {
  Interpreter interp;
  interp.set_position(Pose{1, 2, 3});
  ASSERT_FALSE(interp.open_string("F100 G90 G81 G98 X4 Y5 Z1.5 R2.8\nM2\n"));
  MoveRecorder recorder;
  ASSERT_FALSE(run_program(interp, recorder));
  ASSERT_EQ(recorder.moves.size(), 4U);
  EXPECT_EQ(recorder.moves.front(), "STRAIGHT_TRAVERSE(4.0000, 5.0000, 3.0000)");
  EXPECT_EQ(recorder.moves.back(), "STRAIGHT_TRAVERSE(4.0000, 5.0000, 3.0000)");
}

// The modal-cycle program of the G80 section: eight holes, then G80 and rapid moves home.
TEST(SeedExamples, G80SectionProgram) {
  const auto moves = run_moves(
      "N100 G90 G0 X0 Y0 Z0 (coordinate home)\n"
      "N110 G1 F10 X0 G4 P0.1\n"
      "N120 G81 X1 Y0 Z0 R1 (canned drill cycle)\n"
      "N130 X2\nN140 X3\nN150 X4\nN160 Y1 Z0.5\nN170 X3\nN180 X2\nN190 X1\n"
      "N200 G80 (turn off canned cycle)\n"
      "N210 G0 X0 (rapid home moves)\nN220 Y0\nN220 Z0\nN220 M2 (program end)\n");
  // LinuxCNC's "old Z" is the Z where the run of modal cycles started (0, from N100); the
  // cycles' retracts do not change it, so every hole starts with a move up to R.
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000)", "STRAIGHT_FEED(0.0000, 0.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)", "STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(1.0000, 0.0000, 0.0000)",     "STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000)", "STRAIGHT_TRAVERSE(2.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(2.0000, 0.0000, 0.0000)",     "STRAIGHT_TRAVERSE(2.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(2.0000, 0.0000, 1.0000)", "STRAIGHT_TRAVERSE(3.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(3.0000, 0.0000, 0.0000)",     "STRAIGHT_TRAVERSE(3.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(3.0000, 0.0000, 1.0000)", "STRAIGHT_TRAVERSE(4.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(4.0000, 0.0000, 0.0000)",     "STRAIGHT_TRAVERSE(4.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(4.0000, 0.0000, 1.0000)", "STRAIGHT_TRAVERSE(4.0000, 1.0000, 1.0000)",
      "STRAIGHT_FEED(4.0000, 1.0000, 0.5000)",     "STRAIGHT_TRAVERSE(4.0000, 1.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(4.0000, 1.0000, 1.0000)", "STRAIGHT_TRAVERSE(3.0000, 1.0000, 1.0000)",
      "STRAIGHT_FEED(3.0000, 1.0000, 0.5000)",     "STRAIGHT_TRAVERSE(3.0000, 1.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(3.0000, 1.0000, 1.0000)", "STRAIGHT_TRAVERSE(2.0000, 1.0000, 1.0000)",
      "STRAIGHT_FEED(2.0000, 1.0000, 0.5000)",     "STRAIGHT_TRAVERSE(2.0000, 1.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(2.0000, 1.0000, 1.0000)", "STRAIGHT_TRAVERSE(1.0000, 1.0000, 1.0000)",
      "STRAIGHT_FEED(1.0000, 1.0000, 0.5000)",     "STRAIGHT_TRAVERSE(1.0000, 1.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(0.0000, 1.0000, 1.0000)", "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000)",
  };
  EXPECT_EQ(moves, expected);
}

TEST(SeedExamples, ErrorsUseLinuxCncWording) {
  auto error_of = [](const std::string& program) {
    Interpreter interp;
    EXPECT_FALSE(interp.open_string(program, "bad.ngc"));
    NullSink sink;
    const auto error = run_program(interp, sink);
    return error ? error->to_string() : std::string();
  };
  EXPECT_EQ(error_of("F1 G81 X1 Z2 R1\nM2\n"), "bad.ngc:1: R less than z in cycle in xy plane");
  EXPECT_EQ(error_of("F1\nG81 X1 R1\nM2\n"),
            "bad.ngc:2: Z value unspecified in xy plane canned cycle");
  EXPECT_EQ(error_of("F1 G81 X1 Z-1\nM2\n"), "bad.ngc:1: R clearance plane unspecified in cycle");
  EXPECT_EQ(error_of("G81 X1 Z-1 R1\nM2\n"), "bad.ngc:1: Cannot feed with zero feed rate");
  EXPECT_EQ(error_of("G80 X1\nM2\n"), "bad.ngc:1:1: Cannot use axis values with g80");
  EXPECT_EQ(error_of("G0 X1 X2\nM2\n"), "bad.ngc:1:7: Multiple x words on one line");
  EXPECT_EQ(error_of("G0 X1\n"), "bad.ngc:1: File ended with no percent sign or program end");
}

}  // namespace
}  // namespace cncd::interp
