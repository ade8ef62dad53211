// G33, G33.1, rigid G84/G74 (InterpOptions::rigid_tapping) and G96/G97: the typed commands,
// cncd's own checks and what rs274 cannot run. The canon rs274 gives is in the goldens
// (tests/golden/sync_*, css_*, error_sync_*, error_css_*).
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "cncd/interp/to_machine.hpp"

namespace cncd::interp {
namespace {

struct Recorder final : CanonSink {
  void emit(const CanonCommand& command) override {
    commands.push_back(command);
    const std::string text = format_rs274(command, 3);
    if (!text.empty()) lines.push_back(text);
  }
  template <class T>
  std::vector<T> all() const {
    std::vector<T> found;
    for (const auto& c : commands) {
      if (const auto* op = std::get_if<T>(&c.op)) found.push_back(*op);
    }
    return found;
  }
  // The lines from the first one that starts with `first` on (X Y Z only).
  std::vector<std::string> from(const std::string& first) const {
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].starts_with(first)) return {lines.begin() + static_cast<long>(i), lines.end()};
    }
    return {};
  }
  std::vector<CanonCommand> commands;
  std::vector<std::string> lines;
};

struct Outcome {
  Recorder recorder;
  std::string error;  // "" at a clean end
};

Outcome run(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(std::move(options));
  Outcome out;
  auto error = interp.open_string(program, "s.ngc");
  if (!error) error = run_program(interp, out.recorder);
  if (error) out.error = error->to_string();
  return out;
}

InterpOptions rigid() {
  InterpOptions options;
  options.rigid_tapping = true;
  return options;
}

// --- G33 and G33.1 ------------------------------------------------------------------------

TEST(SpindleSync, G33IsAFeedInStepWithTheSpindle) {
  const auto out = run("G21 S500 M3\nG0 X1 Z2\nG33 Z-10 K1.5\nM2\n");
  ASSERT_EQ(out.error, "");
  const auto synch = out.recorder.all<StartSpeedFeedSynch>();
  ASSERT_EQ(synch.size(), 1U);
  EXPECT_EQ(synch[0].feed_per_rev, 1.5);
  EXPECT_FALSE(synch[0].velocity_mode);
  EXPECT_EQ(out.recorder.from("START_SPEED_FEED_SYNC"),
            (std::vector<std::string>{
                "START_SPEED_FEED_SYNC(1.500000,0)",
                "STRAIGHT_FEED(1.0000, 0.0000, -10.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000)",
                "SET_XY_ROTATION(0.0000)",
                "SET_FEED_MODE(0, 0)",
                "SET_FEED_RATE(0.0000)",
                "STOP_SPINDLE_TURNING(0)",
                "SET_SPINDLE_MODE(0 0.0000)",
                "PROGRAM_END()",
            }));
}

// The pitch reaches the machine in its units.
TEST(SpindleSync, ThePitchIsConvertedToMachineUnits) {
  const auto out = run("G20 S500 M3\nG33 Z-1 K0.05\nM2\n");
  ASSERT_EQ(out.error, "");
  MachineTracker tracker(Units::mm);
  double pitch = 0;
  for (const auto& command : out.recorder.commands) {
    const auto converted = tracker.to_machine(command);
    if (const auto* s = std::get_if<StartSpeedFeedSynch>(&converted.op)) pitch = s->feed_per_rev;
  }
  EXPECT_NEAR(pitch, 1.27, 1e-12);
}

TEST(SpindleSync, G331TapsDownAndBackToWhereItStarted) {
  const auto out =
      run("G21 S500 M3\nG0 X1 Y2 Z3\nG33.1 Z-5 K1.5 I2\nG33.1 Z-6 K1 I0.5\nG33.1 Z-7 K1\n"
          "G1 X4 F100\nM2\n");
  ASSERT_EQ(out.error, "");
  const auto taps = out.recorder.all<RigidTap>();
  ASSERT_EQ(taps.size(), 3U);
  Pose end{};
  end[0] = 1;
  end[1] = 2;
  end[2] = -5;
  EXPECT_EQ(taps[0].end, end);
  EXPECT_EQ(taps[0].scale, 2.0);  // I: faster on the way out
  EXPECT_EQ(taps[1].scale, 1.0);  // never slower
  EXPECT_EQ(taps[2].scale, 1.0);
  EXPECT_EQ(out.recorder.from("STRAIGHT_FEED").front(), "STRAIGHT_FEED(4.0000, 2.0000, 3.0000)");
}

// cncd's own: a move that would wait for ever, or turn an axis the tap leaves out.
TEST(SpindleSync, CncdRefusesWhatWouldNeverFinish) {
  EXPECT_EQ(run("G21 S500 M3\nG33 Z-1 K0\nM2\n").error,
            "s.ngc:2:9: K word must be positive with G33 (the distance per revolution)");
  EXPECT_EQ(run("G21 S500 M3\nG33.1 Z-1 K-1\nM2\n").error,
            "s.ngc:2:11: K word must be positive with G33.1 (the distance per revolution)");
  EXPECT_EQ(run("G21 M3\nG33 Z-1 K1\nM2\n").error,
            "s.ngc:2: Cannot do G33 with zero spindle speed");
  EXPECT_EQ(
      run("G21 S500 M3\nG33.1 Z-1 A10 K1\nM2\n").error,
      "s.ngc:2:11: Cannot move A, B, C, U, V or W with G33.1: the tap moves along X, Y and Z");
  EXPECT_EQ(run("G21 S500 M3\nG33.1 Z-1 A0 K1\nM2\n").error, "");  // A stays where it is
}

// --- G96 and G97 --------------------------------------------------------------------------

TEST(SpindleSync, G96SetsTheSpindleModeAndTheStateShowsIt) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("G21\nG96 D2500 S120\nG96 S100\nG97 S800\nG96 S90\nM2\n", "c.ngc"));
  Recorder r;
  std::vector<int> modes;
  while (interp.step(r) == Interpreter::Step::block)
    modes.push_back(interp.state().gcodes[13]);
  modes.push_back(interp.state().gcodes[13]);
  EXPECT_EQ(modes, (std::vector<int>{970, 960, 960, 970, 960, 970}));
  std::vector<double> max_rpm;
  for (const auto& m : r.all<SetSpindleMode>())
    max_rpm.push_back(m.css_max_rpm);
  EXPECT_EQ(max_rpm, (std::vector<double>{2500, 1e30, 0, 1e30, 0}));  // the last: M2
}

// --- rigid tapping in canned cycles -------------------------------------------------------

TEST(RigidTapping, G84TapsInStepWithTheSpindleFromR) {
  const auto out =
      run("G21 G95 S500 M3\nG0 X0 Y0 Z10\nG98 G84 X1 Y2 Z-5 R2 F1.25\nG80\nM2\n", rigid());
  ASSERT_EQ(out.error, "");
  EXPECT_EQ(out.recorder.from("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)"),
            (std::vector<std::string>{
                "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)",
                "STRAIGHT_TRAVERSE(1.0000, 2.0000, 10.0000)",
                "STRAIGHT_TRAVERSE(1.0000, 2.0000, 2.0000)",
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(1.0000, 2.0000, -5.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "STRAIGHT_TRAVERSE(1.0000, 2.0000, 10.0000)",
                "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)",
                "SET_NAIVECAM_TOLERANCE(0.0000)",
                "COMMENT(\"interpreter: motion mode set to none\")",
                "SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000)",
                "SET_XY_ROTATION(0.0000)",
                "SET_FEED_MODE(0, 0)",
                "SET_FEED_RATE(0.0000)",
                "STOP_SPINDLE_TURNING(0)",
                "SET_SPINDLE_MODE(0 0.0000)",
                "PROGRAM_END()",
            }));
}

// Without the option, G84 stays LinuxCNC's floating cycle.
TEST(RigidTapping, OffByDefault) {
  const auto out = run("G21 G95 S500 M3\nG0 X0 Y0 Z10\nG84 X1 Y2 Z-5 R2 F1.25\nG80\nM2\n");
  ASSERT_EQ(out.error, "");
  EXPECT_TRUE(out.recorder.all<RigidTap>().empty());
  EXPECT_TRUE(out.recorder.all<StartSpeedFeedSynch>().empty());
}

// G94: the pitch is F/S. G99 comes back to R only; L repeats step in G91; G74 taps with M4.
TEST(RigidTapping, PitchInG94RepeatsAndG74) {
  const auto out =
      run("G21 G94 S400 M3 F500\nG0 X0 Y0 Z10\nG91 G99 G84 X10 Z-7 R-8 L2\nG80 G90\n"
          "M4\nG74 X0 Y0 Z-3 R1\nM2\n",
          rigid());
  ASSERT_EQ(out.error, "");
  EXPECT_EQ(out.recorder.from("START_SPEED_FEED_SYNC"),
            (std::vector<std::string>{
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(10.0000, 0.0000, -5.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "STRAIGHT_TRAVERSE(20.0000, 0.0000, 2.0000)",
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(20.0000, 0.0000, -5.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)",
                "SET_NAIVECAM_TOLERANCE(0.0000)",
                "COMMENT(\"interpreter: distance mode changed to absolute\")",
                "COMMENT(\"interpreter: motion mode set to none\")",
                "START_SPINDLE_COUNTERCLOCKWISE(0)",
                "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)",
                "STRAIGHT_TRAVERSE(0.0000, 0.0000, 2.0000)",
                "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(0.0000, 0.0000, -3.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)",
                "SET_NAIVECAM_TOLERANCE(0.0000)",
                "SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000)",
                "SET_XY_ROTATION(0.0000)",
                "SET_FEED_MODE(0, 0)",
                "SET_FEED_RATE(0.0000)",
                "STOP_SPINDLE_TURNING(0)",
                "SET_SPINDLE_MODE(0 0.0000)",
                "PROGRAM_END()",
            }));
}

TEST(RigidTapping, TheSpindleMustTurnTheTapsWay) {
  auto error_of = [](const std::string& program) { return run(program, rigid()).error; };
  EXPECT_EQ(error_of("G21 G94 M3 F500\nG84 X1 Z-5 R2\nM2\n"),
            "s.ngc:2: Cannot do rigid tapping with zero spindle speed in G84: the pitch is F/S in "
            "G94");
  EXPECT_EQ(error_of("G21 G95 M3 F1\nG84 X1 Z-5 R2\nM2\n"),
            "s.ngc:2: Cannot do rigid tapping with zero spindle speed in G84");
  EXPECT_EQ(error_of("G21 S100 F500\nG84 X1 Z-5 R2\nM2\n"), "s.ngc:2: Spindle not turning in G84");
  EXPECT_EQ(error_of("G21 S100 M4 F500\nG84 X1 Z-5 R2\nM2\n"),
            "s.ngc:2: Spindle turning counterclockwise in G84");
  EXPECT_EQ(error_of("G21 S100 M3 F500\nG74 X1 Z-5 R2\nM2\n"),
            "s.ngc:2: Spindle turning clockwise in G74");
  EXPECT_EQ(error_of("G21 G96 S100 M3 F500\nG84 X1 Z-5 R2\nM2\n"),
            "s.ngc:2: Cannot do rigid tapping in G84 with constant surface speed: the pitch is "
            "F/S in G94, with S in rpm (G97)");
  EXPECT_EQ(error_of("G21 G93 S100 M3\nG84 X1 Z-5 R2 F2\nM2\n"),
            "s.ngc:2: Cannot use inverse time feed with canned cycles");
}

// A dwell at the bottom has no place in a rigid tap: the machine reverses there.
TEST(RigidTapping, NoDwellAtTheBottom) {
  const auto out = run("G21 G95 S500 M3 F1\nG84 X1 Z-5 R2 P0.5\nM2\n", rigid());
  ASSERT_EQ(out.error, "");
  EXPECT_TRUE(out.recorder.all<Dwell>().empty());
  EXPECT_EQ(out.recorder.all<RigidTap>().size(), 1U);
}

}  // namespace
}  // namespace cncd::interp
