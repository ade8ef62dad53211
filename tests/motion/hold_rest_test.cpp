// A feed hold or an abort while the path still accelerates comes to rest: the profile brakes to
// a speed of exactly 0, which is what the executor takes for rest, in v / a plus a period.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "cncd/motion/homing.hpp"
#include "machine_fixture.hpp"
#include "profile.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MotionState;
using motion::Move;

// The rapid G0 X123.4 Y56.7 Z-8.9 from machine zero on the small mill (sim_mm.ini's limits):
// 220.6 mm/s reached at 2205.6 mm/s² after 100 ms.
constexpr double kX = 123.4;
constexpr double kY = 56.7;
constexpr double kZ = -8.9;

// The profile alone, sampled at the servo period: accelerating from rest for `periods`
// periods, then held (a limit of 0).
TEST(HoldRest, ProfileBrakingToAZeroLimitEndsAtExactlyZero) {
  const double a = 2205.6;
  int stuck = 0;
  for (int periods = 1; periods < 100; ++periods) {
    double s = 0;
    double v = 0;
    for (int k = 0; k < periods; ++k) {
      double dt = 1e-3;
      motion::advance_profile(s, v, 136.09, 220.56, a, dt);
    }
    const double v_hold = v;
    int k = 0;
    for (; k < 1000 && v != 0.0; ++k) {
      double dt = 1e-3;
      motion::advance_profile(s, v, 136.09, 0.0, a, dt);
    }
    if (v != 0.0) ++stuck;
    EXPECT_EQ(v, 0.0) << "held after " << periods << " periods at " << v_hold << " mm/s";
    EXPECT_LE(k, std::ceil(v_hold / a / 1e-3) + 1) << "held after " << periods << " periods";
  }
  EXPECT_EQ(stuck, 0);
}

// Starts the rapid and lets it run `periods` servo periods.
void start_rapid(VirtualMachine& m, int periods) {
  m.ready();
  m.queue(line_to(Move::Kind::traverse, kX, kY, kZ));
  m.flush();
  m.cycles(periods);
  ASSERT_EQ(m.status().motion, MotionState::moving);
}

// The periods a stop from the speed now may take: v / a and two periods for rounding.
int stop_bound(const VirtualMachine& m) {
  return static_cast<int>(std::ceil(m.status().velocity / 2205.6 / m.period_s())) + 2;
}

TEST(HoldRest, HoldDuringTheRapidsAccelerationPausesAndResumeFinishes) {
  for (int periods = 20; periods <= 90; ++periods) {
    SCOPED_TRACE(periods);
    VirtualMachine m(small_mill());
    ASSERT_NO_FATAL_FAILURE(start_rapid(m, periods));
    const int bound = stop_bound(m);
    m.command(Command::Kind::pause);
    m.cycles(bound);
    ASSERT_EQ(m.status().motion, MotionState::paused) << "speed " << m.status().velocity;
    EXPECT_EQ(m.status().velocity, 0.0);
    const auto held = m.status().commanded;
    m.cycles(50);
    EXPECT_EQ(m.status().commanded, held);
    m.command(Command::Kind::resume);
    m.run_until_idle(10'000);
    EXPECT_EQ(m.status().motion, MotionState::idle);
    EXPECT_DOUBLE_EQ(m.status().commanded[0], kX);
    EXPECT_DOUBLE_EQ(m.status().commanded[1], kY);
    EXPECT_DOUBLE_EQ(m.status().commanded[2], kZ);
  }
}

TEST(HoldRest, AbortDuringTheRapidsAccelerationEndsIdleAndTakesMoves) {
  for (int periods = 20; periods <= 90; ++periods) {
    SCOPED_TRACE(periods);
    VirtualMachine m(small_mill());
    ASSERT_NO_FATAL_FAILURE(start_rapid(m, periods));
    const int bound = stop_bound(m);
    m.command(Command::Kind::abort);
    m.cycles(bound);
    ASSERT_EQ(m.status().motion, MotionState::idle) << "speed " << m.status().velocity;
    EXPECT_EQ(m.status().queued, 0u);
    // The machine takes the next move from where the abort left it.
    m.queue(line_to(Move::Kind::feed, 10, 20, -1, 50));
    m.run_until_idle(10'000);
    EXPECT_DOUBLE_EQ(m.status().commanded[0], 10);
    EXPECT_DOUBLE_EQ(m.status().commanded[1], 20);
  }
}

// X homing, searching at `search` mm/s with `a` mm/s² and its switch out of reach, aborted
// `periods` periods into the search (still speeding up, or at speed).
void abort_search(double a, double search, int periods) {
  SCOPED_TRACE(testing::Message() << "search " << search << " mm/s at " << a << " mm/s², "
                                  << periods << " periods");
  auto config = small_mill();
  config.joints[0].max_acceleration = a;
  config.joints[0].home_search_vel = search;
  config.joints[0].home_latch_vel = 1;
  motion::Homing homing(config, 1e-3, 1u << 0);
  motion::JointIo io;
  ASSERT_TRUE(homing.start(1u << 0, io));
  double before = io.command[0];
  double speed = 0;
  for (int k = 0; k < periods; ++k) {
    io.feedback = io.command;
    ASSERT_EQ(homing.update(io), motion::Homing::Result::running);
    speed = std::abs(io.command[0] - before) / 1e-3;
    before = io.command[0];
  }
  homing.abort();
  const int bound = static_cast<int>(std::ceil(speed / a / 1e-3)) + 2;
  motion::Homing::Result result = motion::Homing::Result::running;
  for (int k = 0; k < bound && result == motion::Homing::Result::running; ++k) {
    io.feedback = io.command;
    result = homing.update(io);
  }
  EXPECT_EQ(result, motion::Homing::Result::aborted) << "from " << speed << " mm/s";
}

// Homing shares the profile: an abort during a switch search brakes the joint to rest and
// ends the homing within v / a and a period.
TEST(HoldRest, HomingAbortDuringTheSearchEnds) {
  int cases = 0;
  for (const double a : {2000.0, 2205.6, 987.65}) {
    for (double search = 7.0; search < 200; search *= 1.07) {
      for (int periods = 1; periods < 120; periods += 7) {
        ASSERT_NO_FATAL_FAILURE(abort_search(a, search, periods));
        ++cases;
      }
    }
  }
  EXPECT_GT(cases, 2000);
}

}  // namespace
}  // namespace cncd::test
