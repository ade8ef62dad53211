// Blending in virtual time: random programs of lines, arcs, helices, corners and dwells under
// random G61.1 / G61 / G64 P never take an axis over its velocity or acceleration limit (finite
// differences of the positions of every period), stay within P of the programmed path, stop
// where they must, hold every dwell and end exactly at the programmed end.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"
#include "path_distance.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Command;
using motion::Move;

double distance(const AxisPose& a, const AxisPose& b) {
  return xyz_distance(a, b);
}

struct Program {
  std::vector<Move> moves;     // line = index + 1
  std::vector<AxisPose> from;  // start of each move
};

// Lines (feeds and traverses, some continuing straight on), arcs and helices tangent or not
// to what comes before, and a few dwells, each move with its own path mode and tolerance.
// `contour`: a G64 contour in XY of lines and arcs, most arcs entered at a corner.
Program random_program(std::mt19937& rng, int count, bool contour = false) {
  std::uniform_real_distribution<double> unit(0, 1);
  Program prog;
  AxisPose at{};
  double heading = 0;
  for (int k = 0; k < count; ++k) {
    Move move;
    move.line = k + 1;
    const double mode = unit(rng);
    move.path_mode = contour      ? Move::PathMode::blend
                     : mode < 0.1 ? Move::PathMode::exact_stop
                     : mode < 0.3 ? Move::PathMode::exact_path
                                  : Move::PathMode::blend;
    move.tolerance = unit(rng) < 0.25 ? 0.0 : 0.005 + 0.5 * unit(rng) * unit(rng);
    move.feed = 10 + 240 * unit(rng);
    move.end = at;
    const double pick = unit(rng);
    if (pick < 0.05 && k > 0 && !contour) {
      move.kind = Move::Kind::dwell;
      move.dwell_s = 0.005 + 0.03 * unit(rng);
    } else if (pick < 0.6) {
      move.kind = unit(rng) < 0.25 ? Move::Kind::traverse : Move::Kind::feed;
      if (unit(rng) > 0.3) heading += (unit(rng) - 0.5) * 2 * std::numbers::pi;
      const double length = 0.05 + 20 * unit(rng) * unit(rng);
      move.end[0] += length * std::cos(heading);
      move.end[1] += length * std::sin(heading);
      if (unit(rng) < 0.2 && !contour) move.end[2] += (unit(rng) - 0.5) * 4;
    } else {
      move.kind = Move::Kind::arc;
      if (unit(rng) < (contour ? 0.8 : 0.3))
        heading += (unit(rng) - 0.5) * 3;  // a corner onto the arc
      const double r = 0.5 + 15 * unit(rng);
      const double sweep = 0.1 + 4 * unit(rng);
      const double side = unit(rng) < 0.5 ? 1 : -1;
      tangent_arc(move, move.end[0], move.end[1], heading, r, sweep, side);
      if (unit(rng) < 0.3 && !contour) move.end[2] += (unit(rng) - 0.5) * 6;  // a helix
    }
    prog.from.push_back(at);
    prog.moves.push_back(move);
    at = move.end;
  }
  return prog;
}

struct Recorded {
  std::vector<AxisPose> points;
  std::vector<int> lines;
  std::vector<double> speeds;  // the path speed the servo loop reports
};

// Queues the program and runs it to the end, recording every period's position and line;
// `pause_at` > 0: a pause at that period and a resume 300 periods later; `override_at` > 0:
// the feed override drops to 0.3 there and goes to 1.5 400 periods later.
Recorded run_program(VirtualMachine& m, const Program& prog, int pause_at, int override_at) {
  Recorded run;
  int period = 0;
  auto step = [&] {
    ++period;
    if (period == pause_at) m.loop().commands().push(Command{Command::Kind::pause, 0});
    if (period == pause_at + 300) m.loop().commands().push(Command{Command::Kind::resume, 0});
    Command command;
    command.kind = Command::Kind::feed_override;
    command.velocity = period == override_at ? 0.3 : 1.5;
    if (override_at > 0 && (period == override_at || period == override_at + 400))
      m.loop().commands().push(command);
    m.cycles(1);
    run.points.push_back(m.status().commanded);
    run.lines.push_back(m.status().line);
    run.speeds.push_back(m.status().velocity);
  };
  for (const auto& move : prog.moves) {
    while (m.loop().segments().size() >= 1000)
      step();
    m.queue(move);
  }
  m.flush();
  do {
    step();
  } while (period < 400000 &&
           (m.status().queued > 0 || m.status().motion != motion::MotionState::idle));
  return run;
}

// Every axis stayed within its limits and the program ended where it was written, every move
// done.
void expect_limits_and_exact_end(const VirtualMachine& m, const AxisPose& start,
                                 const Program& prog) {
  expect_within_limits(m, start);
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_DOUBLE_EQ(m.status().commanded[axis], prog.moves.back().end[axis]);
  EXPECT_EQ(m.status().moves_done, prog.moves.size());
}

// Runs the program (with a pause or an override change in some rounds) and checks the limits,
// the tolerance, the stops, the dwells and the end.
void check_program(const Program& prog, int round) {
  {
    VirtualMachine m(small_mill());
    m.ready();
    const AxisPose start = m.status().commanded;
    const Recorded run = run_program(m, prog, round % 4 == 1 ? 700 : 0, round % 4 == 2 ? 500 : 0);

    expect_limits_and_exact_end(m, start, prog);

    // Within P of the programmed path: a period's position lies on its line's move, or on a
    // blend into it from the move before.
    for (std::size_t k = 0; k < run.points.size(); ++k) {
      const int line = run.lines[k];
      if (line < 1) continue;
      const auto i = static_cast<std::size_t>(line - 1);
      double d = distance_to_move(run.points[k], prog.from[i], prog.moves[i]);
      double allowed = 1e-6;
      if (i > 0) {
        const Move& before = prog.moves[i - 1];
        d = std::min(d, distance_to_move(run.points[k], prog.from[i - 1], before));
        if (before.path_mode == Move::PathMode::blend)
          allowed = before.tolerance > 0 ? before.tolerance + 1e-6 : 1e9;
      }
      ASSERT_LE(d, allowed) << "period " << k << " line " << line;
    }

    // At rest where a move ends under G61.1 or before a dwell; dwells held in full.
    const double dt = m.period_s();
    for (std::size_t i = 0; i + 1 < prog.moves.size(); ++i) {
      const Move& move = prog.moves[i];
      const Move& next = prog.moves[i + 1];
      if (move.kind == Move::Kind::dwell) continue;
      if (move.path_mode != Move::PathMode::exact_stop && next.kind != Move::Kind::dwell) continue;
      std::size_t nearest = 0;
      for (std::size_t k = 1; k < run.points.size(); ++k) {
        if (run.lines[k] != move.line && run.lines[k] != next.line) continue;
        if (nearest == 0 ||
            distance(run.points[k], move.end) < distance(run.points[nearest], move.end))
          nearest = k;
      }
      ASSERT_GT(nearest, 0u) << "end of line " << move.line;
      const double speed = distance(run.points[nearest], run.points[nearest - 1]) / dt;
      EXPECT_LE(speed, 2 * 2000 * dt * std::sqrt(3.0)) << "end of line " << move.line;
      if (next.kind == Move::Kind::dwell) {
        int held = 0, longest = 0;
        for (const auto& point : run.points) {
          held = point == move.end ? held + 1 : 0;
          longest = std::max(longest, held);
        }
        EXPECT_GE(longest + 1, static_cast<int>(next.dwell_s / dt)) << "dwell " << next.line;
      }
    }
  }
}

TEST(Blend, RandomProgramsStayWithinLimitsToleranceAndStops) {
  std::mt19937 rng(2026);
  for (int round = 0; round < 16; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    check_program(random_program(rng, 40), round);
  }
}

// G64 contours in XY where lines meet arcs and arcs meet arcs at corners: the corners get
// fillets (counted from the planner's segments), and the same properties hold.
TEST(Blend, RandomContoursWithLineArcAndArcArcCornersStayWithinLimitsAndTolerance) {
  std::mt19937 rng(4);
  const auto config = small_mill();
  int fillets = 0;
  for (int round = 0; round < 12; ++round) {
    SCOPED_TRACE("contour round " + std::to_string(round));
    const Program prog = random_program(rng, 40, true);
    motion::Planner planner(config);
    planner.reset(AxisPose{});
    std::string error;
    for (const auto& move : prog.moves)
      ASSERT_TRUE(planner.push(move, true, error)) << error;
    planner.flush();
    for (const auto& seg : planner.output())
      fillets += seg.fillet ? 1 : 0;
    check_program(prog, round);
  }
  EXPECT_GE(fillets, 100);
}

// Lines at right angles (a staircase of 10 mm legs at F6000): in G64 P1 the corners are
// rounded by exactly P (the random test checks that the path stays within P) and the run is
// faster than in G61, which stops at every corner.
TEST(Blend, CornersAreRoundedWithinTheToleranceAndFaster) {
  int periods[2] = {};
  for (int k = 0; k < 2; ++k) {
    VirtualMachine m(small_mill());
    m.ready();
    const AxisPose start = m.status().commanded;
    std::vector<AxisPose> corners;
    for (int leg = 1; leg <= 20; ++leg) {
      Move move = line_to(Move::Kind::feed, 10.0 * ((leg + 1) / 2), 10.0 * (leg / 2), 0, 100);
      move.path_mode = k == 0 ? Move::PathMode::blend : Move::PathMode::exact_path;
      move.tolerance = 1.0;
      m.queue(move);
      corners.push_back(move.end);
    }
    periods[k] = m.run_until_idle();
    expect_within_limits(m, start);
    EXPECT_DOUBLE_EQ(m.status().commanded[0], 100);
    EXPECT_DOUBLE_EQ(m.status().commanded[1], 100);
    double nearest = 1e9;  // of the corners inside the path, the closest approach
    for (std::size_t c = 0; c + 1 < corners.size(); ++c) {
      double d = 1e9;
      for (const auto& point : m.trajectory())
        d = std::min(d, distance(point, corners[c]));
      nearest = std::min(nearest, d);
    }
    // The closest point of a blend arc is its middle, P from the corner; the sampled
    // positions come no closer.
    if (k == 0) {
      EXPECT_GE(nearest, 1.0 - 1e-9);
    } else {
      EXPECT_LE(nearest, 0.1);
    }
  }
  EXPECT_LT(periods[0], 0.9 * periods[1]) << periods[0] << " vs " << periods[1];
}

// G64 Q: a line of 0.1 mm steps zigzagging by 0.004 mm runs as one line when Q allows it,
// and as its steps (blended) when it does not; both end exactly at the end.
TEST(Blend, CollinearLinesWithinQAreMerged) {
  for (const double q : {0.01, 0.001}) {
    VirtualMachine m(small_mill());
    m.ready();
    motion::Planner planner(m.config());
    planner.reset(m.status().commanded);
    std::vector<Move> moves;
    for (int k = 1; k <= 200; ++k) {
      Move move = line_to(Move::Kind::feed, 0.1 * k, k % 2 ? 0.004 : 0.0, 0, 100);
      move.path_mode = Move::PathMode::blend;
      move.tolerance = 0.01;
      move.merge_tolerance = q;
      moves.push_back(move);
      std::string error;
      ASSERT_TRUE(planner.push(move, true, error)) << error;
    }
    planner.flush();
    std::uint32_t counted = 0;
    for (const auto& seg : planner.output())
      counted += seg.moves;
    EXPECT_EQ(counted, 200u);
    if (q > 0.004) {
      EXPECT_EQ(planner.output().size(), 1u);
    } else {
      EXPECT_GT(planner.output().size(), 200u);
    }
    const AxisPose start = m.status().commanded;
    for (const auto& move : moves)
      m.queue(move);
    m.run_until_idle();
    expect_within_limits(m, start);
    EXPECT_DOUBLE_EQ(m.status().commanded[0], 20);
    EXPECT_EQ(m.status().moves_done, 200u);
    // Within Q + P of the programmed steps.
    for (const auto& point : m.trajectory()) {
      double d = 1e9;
      for (std::size_t k = 0; k < moves.size(); ++k)
        d = std::min(d, distance_to_move(point, k == 0 ? start : moves[k - 1].end, moves[k]));
      ASSERT_LE(d, q + 0.01 + 1e-9);
    }
  }
}

// Lines into arcs and arcs into arcs a little off tangent (as rounded coordinates leave them):
// under G64 the kinks are crossed at speed within every limit; under G61 each stops.
TEST(Blend, SmallKinksBetweenLinesAndArcsAreCrossedAtSpeed) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Move> chain;
  double x = 0, y = 0, heading = 0;
  for (int k = 0; k < 40; ++k) {
    heading += (unit(rng) < 0.5 ? -1 : 1) * std::pow(10.0, -5 + 3.5 * unit(rng));  // the kink
    Move move;
    move.feed = 250;
    move.tolerance = 0.01;
    if (k % 2 == 0) {
      const double length = 2 + 8 * unit(rng);
      x += length * std::cos(heading);
      y += length * std::sin(heading);
      move.kind = Move::Kind::feed;
    } else {
      const double r = 5 + 10 * unit(rng);
      const double sweep = 0.3 + unit(rng);
      const double side = unit(rng) < 0.5 ? 1 : -1;
      tangent_arc(move, x, y, heading, r, sweep, side);
    }
    move.end = {x, y, 0, 0, 0, 0, 0, 0, 0};
    chain.push_back(move);
  }
  int periods[2] = {};
  for (int k = 0; k < 2; ++k) {
    VirtualMachine m(small_mill());
    m.ready();
    const AxisPose start = m.status().commanded;
    for (auto move : chain) {
      move.path_mode = k == 0 ? Move::PathMode::blend : Move::PathMode::exact_path;
      m.queue(move);
    }
    periods[k] = m.run_until_idle();
    expect_within_limits(m, start);
    EXPECT_DOUBLE_EQ(m.status().commanded[0], chain.back().end[0]);
    EXPECT_DOUBLE_EQ(m.status().commanded[1], chain.back().end[1]);
  }
  EXPECT_LT(periods[0] * 1.3, periods[1]) << periods[0] << " vs " << periods[1];
}

// The same random programs, and random contours of lines and arcs meeting at corners, with
// S-curve profiles ([TRAJ] MAX_LINEAR_JERK): every axis within its limits, every program ends
// exactly, and the path speed's acceleration changes by at most the jerk limit per second
// while the path moves (not in the periods in which it comes to rest, below 1 mm/s: it
// arrives between two periods' ends).
TEST(Blend, SCurveRandomProgramsKeepTheJerkLimit) {
  auto config = small_mill();
  config.scurve = true;
  config.max_linear_jerk = 40000;
  const double dt = 1e-3;
  int moving = 0;
  // Thirty rounds from each of four seeds (18 and 23 ran into a low-acceleration blend seen
  // too late by an earlier search for the limits ahead; in round 92 a braking for a reversal
  // gave up and took its tiny blend arc at 21 times Y's acceleration limit).
  constexpr std::array<unsigned, 4> kSeeds{4711u, 18u, 23u, 217u};
  std::mt19937 rng;
  for (int round = 0; round < 120; ++round) {
    if (round % 30 == 0) rng.seed(kSeeds[static_cast<std::size_t>(round / 30)]);
    const Program prog = random_program(rng, 30, round % 2 == 1);
    VirtualMachine m(config);
    m.ready();
    const AxisPose start = m.status().commanded;
    const Recorded run = run_program(m, prog, round % 4 == 1 ? 700 : 0, round % 4 == 2 ? 500 : 0);
    SCOPED_TRACE("round " + std::to_string(round));
    expect_limits_and_exact_end(m, start, prog);
    // The path speed's second differences (chords would misjudge the speed on tight curves).
    std::vector<double> speed{0, 0};
    speed.insert(speed.end(), run.speeds.begin(), run.speeds.end());
    for (std::size_t k = 2; k < speed.size(); ++k) {
      const double jerk = std::abs(speed[k] - 2 * speed[k - 1] + speed[k - 2]) / (dt * dt);
      if (std::min({speed[k], speed[k - 1], speed[k - 2]}) < 1.0) continue;
      ++moving;
      ASSERT_LE(jerk, config.max_linear_jerk * 1.001 + 1) << "period " << k;
    }
  }
  EXPECT_GT(moving, 300000);
}

}  // namespace
}  // namespace cncd::test
