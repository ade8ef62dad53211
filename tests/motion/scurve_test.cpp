// The S-curve braking arithmetic against a fine step-by-step simulation of the profile it
// describes, and S-curve motion in the servo loop (virtual time): the path's acceleration
// changes by at most MAX_LINEAR_JERK per second, every axis stays within its limits, moves
// end where programmed, and holds, overrides and aborts slow down along S-curves.
#include "scurve.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Command;
using motion::Move;
namespace scurve = motion::scurve;

// Distance in which (v, a) comes down to `target` with the acceleration back at zero, found by
// simulating in 0.1 us steps: jerk down to -accel until ramping back up would just reach the
// target, then ramp up (until the speed passes the target when that comes first).
double simulated_brake(double v, double a, double target, double accel, double jerk) {
  const double dt = 1e-7;
  double s = 0;
  bool easing = false;
  const bool passes = a < 0 && v - a * a / (2 * jerk) <= target;
  for (int i = 0; i < 50'000'000; ++i) {
    if (!easing && a <= 0 && v - a * a / (2 * jerk) <= target) easing = true;
    if (easing && (a >= 0 || (passes && v <= target))) return s;
    double j = easing ? jerk : -jerk;
    if (!easing && a <= -accel) j = 0;
    const double a_next = std::max(-accel, a + j * dt);
    s += v * dt + a * dt * dt / 2 + (a_next - a) * dt * dt / 6;
    v += (a + a_next) / 2 * dt;
    a = a_next;
  }
  return -1;
}

TEST(SCurve, BrakeDistanceMatchesTheProfileItDescribes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int k = 0; k < 20; ++k) {
    const double accel = 500 + 2000 * unit(rng);
    const double jerk = 5000 + 100000 * unit(rng);
    const double v = 200 * unit(rng);
    const double a = (unit(rng) * 2 - 1) * accel;
    const double target = v * unit(rng) * 0.8;
    const double d = scurve::brake_distance(v, a, target, accel, jerk);
    if (scurve::settle_speed(v, a, jerk) <= target && a >= 0) {
      EXPECT_EQ(d, 0.0);
      continue;
    }
    const double sim = simulated_brake(v, a, target, accel, jerk);
    ASSERT_GE(sim, 0);
    EXPECT_NEAR(d, sim, 1e-3 * std::max(1.0, sim))
        << "v " << v << " a " << a << " to " << target << " A " << accel << " J " << jerk;
  }
  // Long brakes hold the acceleration limit; from rest nothing to do.
  EXPECT_NEAR(scurve::brake_distance(200, 0, 0, 2000, 20000), 200.0 * 200 / 4000 + 200 * 0.05,
              1e-9);
  EXPECT_EQ(scurve::brake_distance(0, 0, 0, 2000, 20000), 0.0);
  EXPECT_EQ(scurve::brake_distance(50, 0, 60, 2000, 20000), 0.0);
}

TEST(SCurve, IntegrateStopsAtZeroSpeed) {
  const auto step = scurve::integrate(0.5, -1000, -1000, 0.001);
  EXPECT_EQ(step.velocity, 0.0);
  EXPECT_EQ(step.acceleration, 0.0);
  EXPECT_NEAR(step.distance, 0.5 * 0.5 / 2000, 1e-12);
  const auto free = scurve::integrate(10, 0, 100, 0.001);
  EXPECT_NEAR(free.velocity, 10.05, 1e-12);
  EXPECT_NEAR(free.distance, 0.01 + 1e5 * 1e-9 / 6, 1e-15);
}

config::MachineConfig jerk_mill(double jerk) {
  auto c = small_mill();
  c.max_linear_jerk = jerk;
  c.scurve = true;
  return c;
}

// Path speed, acceleration and jerk by finite differences of the recorded positions.
// `jerk` leaves out the periods around the instants the path comes to rest: it arrives there
// within a period, not on a period's end, and the last period's change in acceleration shows
// a few times the limit (`jerk_at_rest`).
struct PathPeaks {
  double jerk = 0;
  double jerk_at_rest = 0;
  double acceleration = 0;
};
PathPeaks path_peaks(const VirtualMachine& m, const AxisPose& start) {
  const double dt = m.period_s();
  std::vector<AxisPose> points{start, start, start};
  points.insert(points.end(), m.trajectory().begin(), m.trajectory().end());
  std::vector<double> speed;
  for (std::size_t k = 1; k < points.size(); ++k) {
    double sum = 0;
    for (int i = 0; i < 3; ++i)
      sum += (points[k][i] - points[k - 1][i]) * (points[k][i] - points[k - 1][i]);
    speed.push_back(std::sqrt(sum) / dt);
  }
  PathPeaks p;
  for (std::size_t k = 2; k < speed.size(); ++k) {
    const double a1 = (speed[k] - speed[k - 1]) / dt;
    const double a0 = (speed[k - 1] - speed[k - 2]) / dt;
    const double j = std::abs(a1 - a0) / dt;
    p.acceleration = std::max(p.acceleration, std::abs(a1));
    const bool resting = std::min({speed[k], speed[k - 1], speed[k - 2]}) < 1.0;
    (resting ? p.jerk_at_rest : p.jerk) = std::max(resting ? p.jerk_at_rest : p.jerk, j);
  }
  return p;
}

TEST(SCurve, ALineRampsItsAccelerationAtTheJerkLimit) {
  for (const double jerk : {5000.0, 20000.0, 50000.0}) {
    SCOPED_TRACE(jerk);
    VirtualMachine m(jerk_mill(jerk));
    m.ready();
    const AxisPose start = m.status().commanded;
    m.queue(line_to(Move::Kind::feed, 100, 0, 0, 150));
    const int periods = m.run_until_idle();
    EXPECT_DOUBLE_EQ(m.status().commanded[0], 100);
    const auto p = path_peaks(m, start);
    EXPECT_LE(p.jerk, jerk * 1.001 + 1);
    EXPECT_LE(p.jerk_at_rest, jerk * 3);
    EXPECT_LE(peaks(m, start).acceleration, 1.001);
    // Time-optimal within a few periods: cruise at 150 plus the S-curve ramps (each
    // v/a + a/j long when the acceleration limit is reached at v >= a^2/j, else 2 sqrt(v/j)).
    const double ramp =
        150 >= 2000.0 * 2000 / jerk ? 150 / 2000.0 + 2000 / jerk : 2 * std::sqrt(150 / jerk);
    const double ideal = 100 / 150.0 + ramp;
    EXPECT_NEAR(periods * m.period_s(), ideal, 0.006) << periods;
  }
}

// Abort and feed hold mid-move: the path slows to rest along an S-curve and stops on the line.
TEST(SCurve, AbortAndHoldSlowDownAlongAnSCurve) {
  for (const auto kind : {Command::Kind::abort, Command::Kind::pause}) {
    VirtualMachine m(jerk_mill(20000));
    m.ready();
    const AxisPose start = m.status().commanded;
    m.queue(line_to(Move::Kind::feed, 200, 0, 0, 150));
    m.flush();
    m.cycles(400);
    // Pushed rather than through command(), which runs a period without recording it.
    ASSERT_TRUE(m.loop().commands().push(Command{kind, 0}));
    for (int i = 0; i < 1000 && m.status().velocity > 0; ++i)
      m.cycles(1);
    m.cycles(5);
    EXPECT_EQ(m.status().velocity, 0.0);
    EXPECT_EQ(m.status().motion, kind == Command::Kind::abort ? motion::MotionState::idle
                                                              : motion::MotionState::paused);
    EXPECT_LT(m.status().commanded[0], 200);
    EXPECT_EQ(m.status().commanded[1], 0.0);
    const auto p = path_peaks(m, start);
    EXPECT_LE(p.jerk, 20000 * 1.001 + 1);
    EXPECT_LE(peaks(m, start).acceleration, 1.001);
    if (kind == Command::Kind::pause) {
      ASSERT_TRUE(m.loop().commands().push(Command{Command::Kind::resume, 0}));
      m.run_until_idle();
      EXPECT_DOUBLE_EQ(m.status().commanded[0], 200);
      EXPECT_LE(path_peaks(m, start).jerk, 20000 * 1.001 + 1);
    }
  }
}

// A circle of 0.1 mm chords at 150 mm/s under G64: the servo loop passes several chords and
// blend arcs a period, at full feed once up to speed, within every axis's limits and the jerk
// limit, and the whole lap takes the feed-limited time plus the S-curve start and stop.
TEST(SCurve, DenseChordsRunAtFullFeed) {
  VirtualMachine m(jerk_mill(40000));
  m.ready();
  constexpr double kRadius = 30;
  const int chords = static_cast<int>(std::round(2 * std::numbers::pi * kRadius / 0.1));
  m.queue(line_to(Move::Kind::traverse, kRadius, 0, 0));
  m.flush();
  m.run_until_idle();
  m.clear_trajectory();
  const AxisPose at = m.status().commanded;
  int periods = 0;
  for (int i = 1; i <= chords; ++i) {
    const double t = 2 * std::numbers::pi * i / chords;
    Move move = line_to(Move::Kind::feed, kRadius * std::cos(t), kRadius * std::sin(t), 0, 150);
    move.path_mode = Move::PathMode::blend;
    for (; m.loop().segments().size() >= 1000; ++periods)
      m.cycles(1);
    m.queue(move);
  }
  periods += m.run_until_idle();
  EXPECT_NEAR(m.status().commanded[0], kRadius, 1e-9);
  EXPECT_NEAR(m.status().commanded[1], 0, 1e-9);
  expect_within_limits(m, at);
  EXPECT_LE(path_peaks(m, at).jerk, 40000 * 1.001 + 1);
  // 188.5 mm at 150 mm/s, plus a start and a stop: v/a + a/j = 0.125 s.
  const double bound = 2 * std::numbers::pi * kRadius / 150;
  EXPECT_LT(periods * m.period_s(), bound + 0.125 + 0.01) << periods;
}

// 0.1 mm chords of a circle at 150 mm/s under G64, then a retract along Z blended in: the blend
// arc into the retract is tiny and of low tangential acceleration (312 mm/s^2), so the path
// must slow down for it well before the chords' own limits would ask. Found only once it came
// within stopping distance at the chords' acceleration, it was passed at 33 mm/s, 17
// times Z's acceleration limit.
TEST(SCurve, ALowAccelerationBlendFarAheadIsSlowedDownForInTime) {
  VirtualMachine m(jerk_mill(40000));
  m.ready();
  m.queue(line_to(Move::Kind::traverse, 30, 0, 0));
  m.flush();
  m.run_until_idle();
  m.clear_trajectory();
  const AxisPose start = m.status().commanded;
  for (int i = 1; i <= 95; ++i) {
    const double t = 0.1 * i / 30;
    Move chord = line_to(Move::Kind::feed, 30 * std::cos(t), 30 * std::sin(t), 0, 150);
    chord.path_mode = Move::PathMode::blend;
    m.queue(chord);
  }
  Move retract = line_to(Move::Kind::traverse, 30 * std::cos(9.5 / 30), 30 * std::sin(9.5 / 30), 1);
  retract.path_mode = Move::PathMode::blend;
  m.queue(retract);
  m.run_until_idle();
  EXPECT_DOUBLE_EQ(m.status().commanded[2], 1);
  expect_within_limits(m, start);
}

// An 80 mm traverse along X blended into a 5 mm plunge along Z (G64 P0.01): the blend arc is
// tiny, slow and of low tangential acceleration (312 mm/s^2: most of Z's 1000 goes to the
// curvature), but the braking towards it runs along X and may use X's acceleration; only what
// is above the blend's own limit must be ramped off before it. Braking with the blend's limit
// all the way (as one low-acceleration segment ahead once slowed every braking before it) took
// 0.954 s; X alone from rest to rest takes 0.4 + 0.1 + 0.05 s, the plunge about 0.3 s more.
TEST(SCurve, ALowAccelerationBlendDoesNotSlowTheBrakingBeforeIt) {
  VirtualMachine m(jerk_mill(40000));
  m.ready();
  const AxisPose start = m.status().commanded;
  Move along = line_to(Move::Kind::traverse, 80, 0, 0);
  along.path_mode = Move::PathMode::blend;
  along.tolerance = 0.01;
  Move down = line_to(Move::Kind::traverse, 80, 0, -5);
  down.path_mode = Move::PathMode::blend;
  down.tolerance = 0.01;
  m.queue(along);
  m.queue(down);
  const int periods = m.run_until_idle();
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 80);
  EXPECT_DOUBLE_EQ(m.status().commanded[2], -5);
  expect_within_limits(m, start);
  const auto path = path_peaks(m, start);
  EXPECT_LE(path.jerk, 40000 * 1.001 + 1);
  EXPECT_LE(periods, 870) << periods;
}

}  // namespace
}  // namespace cncd::test
