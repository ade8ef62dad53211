// G38.2-G38.5 with a machine that answers (Interpreter::set_probe_result) and the probe file of
// (PROBEOPEN name). What rs274 can show (the canon, its checks, #5061-#5070 and the position
// without a machine) is in the goldens (tests/golden/probe_*, error_probe_*).
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "probe_support.hpp"

namespace cncd::interp {
namespace {

TEST(Probe, EachCodeIsAProbeMoveOfItsKindBetweenProbeOnAndOff) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("G21 F100\nG38.2 Z-1\nG38.3 X1\nG38.4 Y1\nG38.5 Z1\nM2\n", "p.ngc"));
  Recorder r;
  ASSERT_EQ(run_answering(interp, r, {}), "");
  const auto probes = r.all<StraightProbe>();
  ASSERT_EQ(probes.size(), 4U);
  EXPECT_EQ(probes[0].kind, ProbeKind::toward_or_error);
  EXPECT_EQ(probes[1].kind, ProbeKind::toward);
  EXPECT_EQ(probes[2].kind, ProbeKind::away_or_error);
  EXPECT_EQ(probes[3].kind, ProbeKind::away);
  EXPECT_EQ(probes[0].end[2], -1.0);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < r.commands.size(); ++i) {
    const auto& op = r.commands[i].op;
    if (std::holds_alternative<TurnProbeOn>(op) || std::holds_alternative<StraightProbe>(op) ||
        std::holds_alternative<TurnProbeOff>(op)) {
      order.push_back(op.index());
    }
  }
  ASSERT_EQ(order.size(), 12U);
  for (std::size_t i = 0; i < order.size(); i += 3) {
    EXPECT_EQ(order[i], CanonOp(TurnProbeOn{}).index());
    EXPECT_EQ(order[i + 1], CanonOp(StraightProbe{}).index());
    EXPECT_EQ(order[i + 2], CanonOp(TurnProbeOff{}).index());
  }
  EXPECT_EQ(r.commands.back().line, 6);
}

// The next line sees the machine's answer: #5061-#5069 in the program's coordinates and units,
// #5070 whether it tripped, and the position the machine stopped at.
TEST(Probe, TheNextLineSeesTheMachinesAnswer) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("G21 F100\nG10 L2 P1 X10 Y20 Z0\nG0 X0 Y0 Z5\nG38.2 Z-10\n"
                         "(debug, #5061 #5062 #5063 #5070 #<_z>)\nG91 G1 X1\nG20 G90\nG38.3 X1\n"
                         "(debug, #5061 #5063 #5070)\nM2\n",
                         "p.ngc"));
  Recorder r;
  std::vector<CanonCommand> before_answer;
  int probes = 0;
  for (;;) {
    const auto step = interp.step(r);
    ASSERT_NE(step, Interpreter::Step::error) << interp.error()->to_string();
    if (step == Interpreter::Step::end) break;
    if (!r.probed) continue;
    r.probed = false;
    if (++probes == 1) {
      interp.set_probe_result(pose(11, 22, -3.5), true);
      interp.set_machine_position(pose(11, 22, -3.6));
    } else {
      interp.set_probe_result(pose(35.4, 22, -3.6), false);
      interp.set_machine_position(pose(35.4, 22, -3.6));
    }
  }
  const auto texts = r.messages();
  ASSERT_EQ(texts.size(), 2U);
  EXPECT_EQ(texts[0], " 1.000000 2.000000 -3.500000 1.000000 -3.600000");
  // Inches now: the machine's 35.4 mm, less the 10 mm origin, is 1 in; not tripped.
  EXPECT_EQ(texts[1], " 1.000000 -0.141732 0.000000");
  const auto feeds = r.all<StraightFeed>();
  ASSERT_EQ(feeds.size(), 1U);
  EXPECT_EQ(feeds[0].end, pose(2, 2, -3.6));  // from where the machine stopped
}

// Without an answer, step() reads on as LinuxCNC's standalone rs274: the programmed end in
// #5061-#5069 and 0 in #5070, whatever an earlier answer left there.
TEST(Probe, WithoutAnAnswerTheNextLineReadsAsRs274GivesIt) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string(
      "G21 F100\nG38.2 Z-4\n(debug, #5063 #5070)\nG38.2 X3\n(debug, #5061 #5063 #5070 #<_z>)\n"
      "M2\n",
      "p.ngc"));
  Recorder r;
  int probes = 0;
  for (;;) {
    const auto step = interp.step(r);
    ASSERT_NE(step, Interpreter::Step::error) << interp.error()->to_string();
    if (step == Interpreter::Step::end) break;
    if (r.probed && ++probes == 1) interp.set_probe_result(pose(0, 0, -2), true);
    r.probed = false;
  }
  const auto texts = r.messages();
  ASSERT_EQ(texts.size(), 2U);
  EXPECT_EQ(texts[0], " -2.000000 1.000000");
  EXPECT_EQ(texts[1], " 3.000000 -4.000000 0.000000 -4.000000");
}

TEST(Probe, InverseTimeIsRefused) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string("G21 F100\nG93 G38.2 Z-1 F2\nM2\n", "p.ngc"));
  NullSink sink;
  const auto error = run_program(interp, sink);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->to_string(), "p.ngc:2: Cannot probe in inverse time feed mode");
}

// A probe is a move: a loop of probes is no endless loop without motion.
TEST(Probe, ALoopOfProbesIsNoLoopWithoutMotion) {
  InterpOptions options;
  options.max_loops_without_motion = 10;
  Interpreter interp(options);
  ASSERT_FALSE(interp.open_string(
      "G21 F100\n#1=0\nO1 while [#1 LT 20]\nG38.3 Z[-1-#1]\n#1=[#1+1]\nO1 endwhile\nM2\n",
      "p.ngc"));
  Recorder r;
  EXPECT_EQ(run_answering(interp, r, {}), "");
  EXPECT_EQ(r.all<StraightProbe>().size(), 20U);
}

}  // namespace
}  // namespace cncd::interp
