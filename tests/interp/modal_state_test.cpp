// M70-M73 where cncd restores what was saved and LinuxCNC's rs274 does not (the golden cases
// hold the rest), and the lines cncd refuses where rs274 would skip words.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

struct Outcome {
  std::string canon;
  std::string error;
};

Outcome run(const std::string& program, Dialect dialect = Dialect::linuxcnc) {
  InterpOptions options;
  options.dialect = dialect;
  Interpreter interp(options);
  std::ostringstream out;
  Rs274Printer printer(out);
  Outcome outcome;
  if (auto error = interp.open_string(program, "modal.ngc")) {
    outcome.error = error->to_string();
  } else if (auto failed = run_program(interp, printer)) {
    outcome.error = failed->to_string();
  }
  outcome.canon = out.str();
  return outcome;
}

// The canon a "M72 (restore)" line printed, up to the "(done)" line after it.
std::string restored(const std::string& program) {
  const Outcome out = run(program);
  EXPECT_EQ(out.error, "");
  const std::string from = "COMMENT(\"restore\")\n";
  const auto begin = out.canon.find(from);
  const auto end = out.canon.find("COMMENT(\"done\")\n");
  if (begin == std::string::npos || end == std::string::npos || end < begin) return out.canon;
  return out.canon.substr(begin + from.size(), end - begin - from.size());
}

// rs274 drops the rest of an M72 line once the restore changed something: M72 G0 X1 never
// moves, M72 M2 never ends the program.
TEST(ModalState, AnM72LineTakesNoOtherWords) {
  const Outcome moved = run("F1\nM70\nF3\nM72 G0 X1\nM2\n");
  EXPECT_NE(moved.error.find("modal.ngc:4:1: An M72 line takes no other words"), std::string::npos)
      << moved.error;
  EXPECT_EQ(moved.canon.find("STRAIGHT_TRAVERSE"), std::string::npos);
  EXPECT_NE(run("F1\nM70\nM72 M2\n").error.find("no other words"), std::string::npos);
  EXPECT_NE(run("M70\nM72 M8\nM2\n").error.find("no other words"), std::string::npos);
  EXPECT_EQ(run("M70\nN10 M72 (comment)\n#1 = 2\nM2\n").error, "");
}

TEST(ModalState, M72WithNothingSavedNamesTheLine) {
  EXPECT_NE(run("G0 X1\nM70\nM71\nM72\nM2\n")
                .error.find("modal.ngc:4:1: Cannot restore context from invalid stack frame"),
            std::string::npos);
}

// rs274 leaves the feed at 0 when the feed mode it restores was not in force (from G93, or
// G95 back to G94 with the same F), so the next G1 fails "Cannot do g1 with zero feed rate".
TEST(ModalState, TheFeedComesBackWithItsMode) {
  EXPECT_EQ(restored("F10\nM70\nG93 F3\nM72 (restore)\n(done)\nG1 X1\nM2\n"),
            "COMMENT(\"interpreter: feed mode set to units per minute\")\n"
            "SET_FEED_MODE(0, 0)\nSET_FEED_RATE(0.0000)\nSET_FEED_RATE(10.0000)\n");
  EXPECT_EQ(restored("F5\nM70\nG95\nF5\nM72 (restore)\n(done)\nG1 X1\nM2\n"),
            "COMMENT(\"interpreter: feed mode set to units per minute\")\n"
            "SET_FEED_MODE(0, 0)\nSET_FEED_RATE(0.0000)\nSET_FEED_RATE(5.0000)\n");
  EXPECT_EQ(run("F5\nM70\nG95\nF5\nM72\nG1 X1\nM2\n").error, "");
}

// rs274 restores G96 without its D: a limit of 1e30 rpm.
TEST(ModalState, ConstantSurfaceSpeedKeepsItsRpmLimit) {
  EXPECT_EQ(restored("G96 S300 D2000\nM70\nG97 S10\nM72 (restore)\n(done)\nM2\n"),
            "SET_SPINDLE_MODE(0 2000.0000)\nSET_SPINDLE_SPEED(0, 300.0000)\n");
}

// rs274 restores G43.1 as G43, the table's offset of the tool in the spindle.
TEST(ModalState, G43Point1ComesBackWithItsOffsets) {
  EXPECT_EQ(restored("G43.1 Z2\nM70\nG49\nM72 (restore)\n(done)\nM2\n"),
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 2.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 "
            "0.0000)\n");
}

// The same for G43.2: the offsets it added, not the tool's alone.
TEST(ModalState, G43Point2ComesBackWithTheOffsetsItAdded) {
  EXPECT_EQ(restored("G43.1 Z2\nG43.2 Z0.5 X0.25\nM70\nG49\nM72 (restore)\n(done)\nM2\n"),
            "USE_TOOL_LENGTH_OFFSET(0.2500 0.0000 2.5000, 0.0000 0.0000 0.0000, 0.0000 0.0000 "
            "0.0000)\n");
}

// G43.2 with axis words adds them to the offsets in force. The rs274 of Debian 12 (LinuxCNC
// 2.9.0~pre1) refuses that form with "Requested tool -1 not found in the tool table", a defect
// LinuxCNC fixed later in 2.9 (it reads the missing H word as tool -1).
TEST(ModalState, G43Point2AddsTheLinesAxisWords) {
  const Outcome out = run("G43.1 Z2\nG43.2 Z0.5 X0.25\nG43.2 Z-0.1\nG0 X1 Z1\nM2\n");
  EXPECT_EQ(out.error, "");
  EXPECT_NE(out.canon.find("USE_TOOL_LENGTH_OFFSET(0.2500 0.0000 2.4000, "), std::string::npos)
      << out.canon;
  EXPECT_NE(out.canon.find("STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000, "), std::string::npos)
      << out.canon;
}

// rs274 turns nothing off while some saved coolant was on: M7 saved, M8 then, both stay on.
TEST(ModalState, CoolantThatWasOffIsTurnedOff) {
  EXPECT_EQ(restored("M7\nM70\nM8\nM72 (restore)\n(done)\nM2\n"),
            "MIST_OFF()\nFLOOD_OFF()\nMIST_ON()\n");
  EXPECT_EQ(restored("M8\nM70\nM9\nM7\nM72 (restore)\n(done)\nM2\n"),
            "MIST_OFF()\nFLOOD_OFF()\nFLOOD_ON()\n");
  EXPECT_EQ(restored("M8\nM70\nM9\nM72 (restore)\n(done)\nM2\n"), "FLOOD_ON()\n");
}

// rs274 restores M49 as ENABLE_SPEED_OVERRIDE and M50-M53 not at all.
TEST(ModalState, OverrideSwitchesComeBackAsSaved) {
  EXPECT_EQ(restored("M49\nM70\nM48\nM72 (restore)\n(done)\nM2\n"),
            "DISABLE_FEED_OVERRIDE()\nDISABLE_SPEED_OVERRIDE(0)\n");
  EXPECT_EQ(restored("M70\nM50 P0\nM52 P1\nM53 P0\nM72 (restore)\n(done)\nM2\n"),
            "ENABLE_FEED_OVERRIDE()\nDISABLE_ADAPTIVE_FEED()\nENABLE_FEED_HOLD()\n");
}

TEST(ModalState, TheNumeryxDialectRefusesThem) {
  for (const char* code : {"M70", "M71", "M72", "M73"}) {
    const Outcome out = run(std::string(code) + "\nM2\n", Dialect::numeryx);
    EXPECT_NE(out.error.find(std::string(code) + " is not supported in the Numeryx dialect"),
              std::string::npos)
        << out.error;
  }
}

}  // namespace
}  // namespace cncd::interp
