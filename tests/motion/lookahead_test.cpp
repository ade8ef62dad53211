// Look-ahead in virtual time: with G61/G64 the path goes on at speed through tangent
// junctions (a line split in pieces, lines tangent to arcs, arcs to arcs), every axis within
// its limits at every period, ending exactly at the programmed end; G61.1 still stops.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::Move;

// Queues every move, running the loop whenever the ring is nearly full.
void feed_all(VirtualMachine& m, const std::vector<Move>& moves) {
  for (const auto& move : moves) {
    while (m.loop().segments().size() >= 1000)
      m.cycles(1);
    m.queue(move);
  }
}

std::vector<Move> split_line(double length, double piece, double feed, bool continuous) {
  std::vector<Move> moves;
  const int n = static_cast<int>(std::lround(length / piece));
  for (int k = 1; k <= n; ++k) {
    Move move = line_to(Move::Kind::feed, length * k / n, 0, 0, feed);
    move.path_mode = continuous ? Move::PathMode::blend : Move::PathMode::exact_stop;
    moves.push_back(move);
  }
  return moves;
}

TEST(LookAhead, ALineInShortPiecesRunsAsFastAsInOne) {
  VirtualMachine whole(small_mill());
  whole.ready();
  whole.queue(line_to(Move::Kind::feed, 300, 0, 0, 150));
  const int one = whole.run_until_idle();

  VirtualMachine pieces(small_mill());
  pieces.ready();
  const auto start = pieces.status().commanded;
  feed_all(pieces, split_line(300, 0.1, 150, true));
  pieces.run_until_idle();
  // The same time as one move, give or take a period for the pieces' rounding.
  EXPECT_LE(static_cast<int>(pieces.trajectory().size()), one + 2);
  const auto p = peaks(pieces, start);
  EXPECT_LE(p.velocity, 1.001);
  EXPECT_LE(p.acceleration, 1.001);
  EXPECT_DOUBLE_EQ(pieces.status().commanded[0], 300);
  EXPECT_EQ(pieces.status().segments_done, 3000u);
}

TEST(LookAhead, ExactStopModeStopsAtEveryJunction) {
  VirtualMachine m(small_mill());
  m.ready();
  feed_all(m, split_line(20, 1, 150, false));
  m.run_until_idle();
  // 20 rest-to-rest moves of 1 mm: each at least 2 * sqrt(1 mm / 2000 mm/s^2) = 44.7 ms.
  EXPECT_GE(static_cast<int>(m.trajectory().size()), 20 * 44);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 20);
}

// A random chain of lines and arcs in XY, each tangent to the one before, some with Z rising
// (helices, whose start is not tangent to a flat move before them), random feeds.
std::vector<Move> tangent_chain(std::mt19937& rng, int count, bool continuous) {
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Move> moves;
  double x = 0, y = 0, z = 0, heading = 0;
  for (int k = 0; k < count; ++k) {
    Move move;
    move.path_mode = continuous ? Move::PathMode::blend : Move::PathMode::exact_stop;
    move.feed = 5 + 250 * unit(rng);
    if (unit(rng) < 0.5) {
      const double length = 0.05 + 15 * unit(rng) * unit(rng);
      x += length * std::cos(heading);
      y += length * std::sin(heading);
      move.kind = Move::Kind::feed;
    } else {
      const double r = 1 + 14 * unit(rng);
      const double sweep = 0.05 + 3 * unit(rng);
      const bool ccw = unit(rng) < 0.5;
      tangent_arc(move, x, y, heading, r, sweep, ccw ? 1 : -1);
      if (unit(rng) < 0.2) z += 3 * unit(rng);
    }
    move.end = {x, y, z, 0, 0, 0, 0, 0, 0};
    moves.push_back(move);
  }
  return moves;
}

TEST(LookAhead, RandomTangentChainsStayWithinEveryLimitAndEndExactly) {
  std::mt19937 rng(4242);
  for (int round = 0; round < 12; ++round) {
    const bool continuous = round % 4 != 3;
    const auto moves = tangent_chain(rng, 30, continuous);
    VirtualMachine m(small_mill());
    m.ready();
    const auto start = m.status().commanded;
    feed_all(m, moves);
    if (round % 3 == 1) {  // overrides dropped and raised while moving
      m.cycles(150);
      Command command;
      command.kind = Command::Kind::feed_override;
      command.velocity = 0.1;
      ASSERT_TRUE(m.loop().commands().push(command));
      m.cycles(200);
      command.velocity = 1.0;
      ASSERT_TRUE(m.loop().commands().push(command));
    }
    if (round % 3 == 2) {  // a pause across junctions, then resume
      m.cycles(200);
      // Pushed and run by cycles() so that every period is recorded.
      ASSERT_TRUE(m.loop().commands().push(Command{Command::Kind::pause, 0}));
      m.cycles(300);
      EXPECT_EQ(m.status().velocity, 0) << "round " << round;
      ASSERT_TRUE(m.loop().commands().push(Command{Command::Kind::resume, 0}));
    }
    m.run_until_idle();
    const auto p = peaks(m, start);
    EXPECT_LE(p.velocity, 1.001) << "round " << round;
    EXPECT_LE(p.acceleration, 1.001) << "round " << round;
    for (int axis = 0; axis < 3; ++axis)
      EXPECT_DOUBLE_EQ(m.status().commanded[axis], moves.back().end[axis]) << "round " << round;
  }
}

TEST(LookAhead, TangentJunctionsAreCrossedAtSpeedOnlyWhenContinuous) {
  // A line then a tangent quarter circle of radius 50 (full feed fits its curvature).
  for (const bool continuous : {true, false}) {
    VirtualMachine m(small_mill());
    m.ready();
    Move line = line_to(Move::Kind::feed, 50, 0, 0, 100);
    line.path_mode = continuous ? Move::PathMode::blend : Move::PathMode::exact_stop;
    Move arc = line_to(Move::Kind::feed, 100, 50, 0, 100);
    arc.kind = Move::Kind::arc;
    arc.center_first = 50;
    arc.center_second = 50;
    arc.turns = 1;
    arc.path_mode = continuous ? Move::PathMode::blend : Move::PathMode::exact_stop;
    m.queue(line);
    m.queue(arc);
    m.flush();
    double slowest_at_junction = 1e9;
    for (int k = 0; k < 5000 && (k == 0 || m.status().queued > 0); ++k) {
      m.cycles(1);
      const auto s = m.status();
      if (std::abs(s.commanded[0] - 50) < 0.3 && s.commanded[1] < 0.3)
        slowest_at_junction = std::min(slowest_at_junction, s.velocity);
    }
    if (continuous) {
      EXPECT_NEAR(slowest_at_junction, 100, 1e-6);
    } else {
      EXPECT_LT(slowest_at_junction, 25);
    }
    EXPECT_DOUBLE_EQ(m.status().commanded[0], 100);
    EXPECT_DOUBLE_EQ(m.status().commanded[1], 50);
  }
}

TEST(LookAhead, TangentChainsRunFasterThanWithExactStops) {
  std::mt19937 rng(77);
  const auto chain = tangent_chain(rng, 40, true);
  auto stops = chain;
  for (auto& move : stops)
    move.path_mode = Move::PathMode::exact_stop;
  int cycles[2] = {};
  int crossed_moving[2] = {};
  for (int k = 0; k < 2; ++k) {
    VirtualMachine m(small_mill());
    m.ready();
    feed_all(m, k == 0 ? chain : stops);
    m.flush();
    std::uint64_t done = 0;
    do {
      m.cycles(1);
      ++cycles[k];
      if (m.status().segments_done != done && m.status().velocity > 5) ++crossed_moving[k];
      done = m.status().segments_done;
    } while (m.status().queued > 0 && cycles[k] < 100000);
  }
  // Most of the 39 junctions are tangent (those onto and off a helix are not); a stop is
  // followed within the period by at most 2 mm/s.
  EXPECT_GE(crossed_moving[0], 25);
  EXPECT_EQ(crossed_moving[1], 0);
  EXPECT_LT(cycles[0] * 1.1, cycles[1]) << cycles[0] << " vs " << cycles[1];
}

}  // namespace
}  // namespace cncd::test
