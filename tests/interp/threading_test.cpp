// G76: the typed commands of its passes, and cncd's own refusals of threads rs274 runs into
// motion no machine should make. The canon rs274 gives is in the goldens
// (tests/golden/lathe_g76_*, error_g76_*).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"

namespace cncd::interp {
namespace {

// The commands of a program and its error ("" at a clean end).
struct Thread final : CanonSink {
  void emit(const CanonCommand& command) override { ops.push_back(command.op); }
  std::vector<CanonOp> ops;
  std::string error;
};

Thread cut(const std::string& lines) {
  Thread t;
  Interpreter interp;
  const std::string program = "G18 G21 G90\nS300 M3\nG0 X7 Z3\n" + lines + "\nM2\n";
  auto error = interp.open_string(program, "t.ngc");
  if (!error) error = run_program(interp, t);
  if (error) t.error = error->message;
  return t;
}

std::string refusal(const std::string& lines) {
  return cut(lines).error;
}

TEST(Threading, PassesRunInStepWithTheSpindleWithTheFeedOverrideOff) {
  const Thread t = cut("G76 P1.75 Z-20 I-1 J0.2 K1.07 R1.5 E1 L3");
  ASSERT_EQ(t.error, "");
  bool synced = false;
  bool override_on = true;
  int passes = 0;
  std::vector<double> depths;  // the deepest X of each pass
  double deepest = 0;
  for (const CanonOp& op : t.ops) {
    if (const auto* s = std::get_if<StartSpeedFeedSynch>(&op)) {
      if (!synced) {
        ++passes;
        deepest = 1e9;
      }
      synced = true;
      // The thread at P, the tapers steeper by their length over E.
      const bool thread = s->feed_per_rev == 1.75;
      EXPECT_TRUE(thread || std::abs(s->feed_per_rev - 1.75 * std::hypot(1.07, 1.0)) < 1e-12)
          << s->feed_per_rev;
      EXPECT_FALSE(override_on);
    } else if (std::holds_alternative<StopSpeedFeedSynch>(op)) {
      synced = false;
      depths.push_back(deepest);
    } else if (const auto* e = std::get_if<SetFeedOverrideEnable>(&op)) {
      override_on = e->on;
    } else if (const auto* f = std::get_if<StraightFeed>(&op)) {
      EXPECT_TRUE(synced) << "every feed of G76 follows the spindle";
      deepest = std::min(deepest, f->end[0]);
    } else if (std::holds_alternative<StraightTraverse>(op)) {
      EXPECT_FALSE(synced);
    }
  }
  EXPECT_TRUE(override_on);
  // J 0.2 x n^(1/1.5) while short of 1.07 (5.35^1.5 = 12.4): n = 1..12, then the full depth.
  ASSERT_EQ(passes, 13);
  ASSERT_EQ(depths.size(), 13u);
  for (int n = 1; n <= 12; ++n) {
    EXPECT_NEAR(depths[static_cast<std::size_t>(n - 1)], 6.0 - 0.2 * std::pow(n, 1 / 1.5), 1e-12);
  }
  EXPECT_NEAR(depths[12], 6.0 - 1.07, 1e-12);
  // It ends at Z on the drive line.
  const StraightTraverse* out = nullptr;
  for (const CanonOp& op : t.ops) {
    if (const auto* m = std::get_if<StraightTraverse>(&op)) out = m;
  }
  ASSERT_NE(out, nullptr);
  EXPECT_EQ(out->end[0], 7.0);
  EXPECT_EQ(out->end[2], -20.0);
}

TEST(Threading, RefusesWhatRs274RunsIntoNonsense) {
  EXPECT_EQ(refusal("G0 X8\nG41 G0 X7 Z2\nG76 P1 Z-10 I-0.5 J0.1 K0.6"),
            "Cannot use G76 with cutter radius compensation on");
  EXPECT_EQ(refusal("G17 G76 P1 Z-10 I-0.5 J0.1 K0.6"),
            "G76 cuts in the XZ plane: select it with G18 first");
  EXPECT_EQ(refusal("G76 P0 Z-10 I-0.5 J0.1 K0.6"),
            "P word must be positive with G76 (the distance per revolution)");
  EXPECT_EQ(refusal("G76 P-2 Z-10 I-0.5 J0.1 K0.6"),
            "P word must be positive with G76 (the distance per revolution)");
  EXPECT_EQ(refusal("S0 G76 P1 Z-10 I-0.5 J0.1 K0.6"), "Cannot do G76 with zero spindle speed");
  EXPECT_EQ(refusal("G76 P1 X5 Z-10 I-0.5 J0.1 K0.6"),
            "Cannot put an X in G76: the drive line starts where the tool stands");
  EXPECT_EQ(refusal("G76 P1 Y5 Z-10 I-0.5 J0.1 K0.6"),
            "Cannot put a Y in G76: the drive line starts where the tool stands");
  EXPECT_EQ(refusal("G76 P1 Z3 I-0.5 J0.1 K0.6"),
            "Cannot do G76 with Z where the tool stands: the thread has no length");
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 E1 L4"),
            "L word must be 0, 1, 2 or 3 with G76 (no taper, entry, exit, both)");
  // Z3 to Z-10: two tapers of 6.5 fit, of 6.6 not; one of 13 fits.
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 E6.5 L3"), "");
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 E6.6 L3"),
            "E word too long with G76: the tapers would be longer than the thread");
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 E13 L2"), "");
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 E13.1 L1"),
            "E word too long with G76: the tapers would be longer than the thread");
  // rs274 takes I, J and K as a quarter of themselves when G7 comes on the G76 line, and as
  // twice when G8 does.
  EXPECT_EQ(refusal("G7 G76 P1 Z-10 I-0.5 J0.1 K0.6"),
            "Cannot change the lathe diameter mode (G7, G8) on a G76 line");
  EXPECT_EQ(refusal("G7\nG8 G76 P1 Z-10 I-0.5 J0.1 K0.6"),
            "Cannot change the lathe diameter mode (G7, G8) on a G76 line");
  EXPECT_EQ(refusal("G8 G76 P1 Z-10 I-0.5 J0.1 K0.6"), "");
  // Passes without end: a J far too small for K at a steep degression, or a huge H.
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.001 K1 R3"),
            "G76 would cut more than 10000 passes: J too small for K at this R, or H too large");
  EXPECT_EQ(refusal("G76 P1 Z-10 I-0.5 J0.1 K0.6 H20000"),
            "G76 would cut more than 10000 passes: J too small for K at this R, or H too large");
}

TEST(Threading, UnderG7TheDepthsAreDiameters) {
  const Thread radius = cut("G76 P1 Z-10 I-0.5 J0.1 K0.6 Q29.5 E1 L3");
  const Thread diameter = cut("G7\nG76 P1 Z-10 I-1 J0.2 K1.2 Q29.5 E1 L3");
  ASSERT_EQ(radius.error, "");
  ASSERT_EQ(diameter.error, "");
  std::vector<Pose> a, b;
  for (const auto* ops : {&radius.ops, &diameter.ops}) {
    auto& ends = ops == &radius.ops ? a : b;
    for (const CanonOp& op : *ops) {
      if (const auto* f = std::get_if<StraightFeed>(&op)) ends.push_back(f->end);
    }
  }
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t n = 0; n < a.size(); ++n) {
    EXPECT_NEAR(a[n][0], b[n][0], 1e-12) << n;
    EXPECT_NEAR(a[n][2], b[n][2], 1e-12) << n;
  }
}

}  // namespace
}  // namespace cncd::interp
