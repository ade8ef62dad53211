// The path executor alone: segments built by hand, pushed to its ring and followed period by
// period, without joints, drives or a servo loop.
#include "cncd/motion/path_executor.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::motion {
namespace {

constexpr double kDt = 1e-3;

Segment line(const AxisPose& from, const AxisPose& to, double feed = 0, bool continuous = false) {
  Segment s;
  s.kind = Segment::Kind::line;
  s.start = from;
  s.end = to;
  double sum = 0;
  for (int i = 0; i < kAxes; ++i)
    sum += (to[i] - from[i]) * (to[i] - from[i]);
  s.length = std::sqrt(sum);
  s.axis_velocity = 100;
  s.feed = feed;
  s.max_velocity = feed > 0 ? std::min(feed, s.axis_velocity) : s.axis_velocity;
  s.max_acceleration = 1000;
  s.continuous = continuous;
  return s;
}

AxisPose at(double x, double y = 0) {
  AxisPose p{};
  p[0] = x;
  p[1] = y;
  return p;
}

struct PathRun {
  std::vector<double> velocity;  // per period
  std::vector<AxisPose> poses;
  PathExecutor::Result last;
  int periods = 0;
};

// Advances until the path is idle with nothing pending, or `max_periods`.
PathRun run(PathExecutor& path, AxisPose& pose, int max_periods = 100'000) {
  PathRun r;
  while (r.periods < max_periods) {
    r.last = path.advance(kDt, pose, false);
    ++r.periods;
    r.velocity.push_back(path.velocity());
    r.poses.push_back(pose);
    if (r.last.fault != PathExecutor::Fault::none) break;
    if (!path.pending() && path.motion() == MotionState::idle) break;
  }
  return r;
}

std::unique_ptr<PathExecutor> make(const config::MachineConfig& config) {
  return std::make_unique<PathExecutor>(config, kDt);
}

TEST(PathExecutor, RunsALineToItsEndWithinItsLimits) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  Segment s = line(at(0), at(20));
  s.line = 7;
  ASSERT_TRUE(path->segments().push(s));
  EXPECT_TRUE(path->pending());
  const PathRun r = run(*path, pose);
  EXPECT_EQ(r.last.fault, PathExecutor::Fault::none);
  EXPECT_DOUBLE_EQ(pose[0], 20.0);
  EXPECT_EQ(path->segments_done(), 1u);
  EXPECT_EQ(path->moves_done(), 1u);
  EXPECT_EQ(path->line(), 7);
  EXPECT_EQ(path->queued(), 0u);
  EXPECT_FALSE(path->active());
  const double peak = *std::max_element(r.velocity.begin(), r.velocity.end());
  EXPECT_NEAR(peak, 100.0, 1e-9);
  // 20 mm at 100 mm/s with 0.1 s ramps at each end: 0.3 s.
  EXPECT_NEAR(r.periods, 300, 3);
  for (std::size_t k = 1; k < r.velocity.size(); ++k)
    EXPECT_LE(std::abs(r.velocity[k] - r.velocity[k - 1]), 1000 * kDt + 1e-9) << k;
}

// Queues two lines along X, from 0 to `mid` and on to `end`, the first one blending.
void push_two_lines(PathExecutor& path, double mid, double end) {
  ASSERT_TRUE(path.segments().push(line(at(0), at(mid), 0, true)));
  ASSERT_TRUE(path.segments().push(line(at(mid), at(end))));
}

TEST(PathExecutor, CrossesATangentJunctionAtSpeed) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  ASSERT_NO_FATAL_FAILURE(push_two_lines(*path, 20, 40));
  const PathRun r = run(*path, pose);
  EXPECT_DOUBLE_EQ(pose[0], 40.0);
  EXPECT_EQ(path->segments_done(), 2u);
  // Never at rest between the two: 40 mm at full speed with one ramp at each end.
  EXPECT_NEAR(r.periods, 500, 3);
  for (std::size_t k = 5; k + 5 < r.velocity.size(); ++k)
    EXPECT_GT(r.velocity[k], 0.0) << k;
}

TEST(PathExecutor, StopsAtAnExactStopJunction) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  ASSERT_TRUE(path->segments().push(line(at(0), at(20))));
  ASSERT_TRUE(path->segments().push(line(at(20), at(20, 20))));
  const PathRun r = run(*path, pose);
  EXPECT_DOUBLE_EQ(pose[1], 20.0);
  // Two moves of 0.3 s each, the second from rest.
  EXPECT_NEAR(r.periods, 600, 4);
  EXPECT_LT(*std::min_element(r.velocity.begin() + 250, r.velocity.begin() + 350), 1.0);
}

TEST(PathExecutor, FeedOverrideScalesAFeedMove) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  path->set_overrides(0.5, 1.0);
  ASSERT_TRUE(path->segments().push(line(at(0), at(20), 60)));
  const PathRun r = run(*path, pose);
  EXPECT_DOUBLE_EQ(pose[0], 20.0);
  EXPECT_NEAR(*std::max_element(r.velocity.begin(), r.velocity.end()), 30.0, 1e-9);
}

TEST(PathExecutor, RapidOverrideScalesATraverse) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  path->set_overrides(1.0, 0.25);
  ASSERT_TRUE(path->segments().push(line(at(0), at(20))));
  const PathRun r = run(*path, pose);
  EXPECT_NEAR(*std::max_element(r.velocity.begin(), r.velocity.end()), 25.0, 1e-9);
}

TEST(PathExecutor, PauseHoldsThePathAndResumeFinishesIt) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  ASSERT_TRUE(path->segments().push(line(at(0), at(50))));
  for (int k = 0; k < 150; ++k)
    path->advance(kDt, pose, false);
  EXPECT_EQ(path->motion(), MotionState::moving);
  path->pause();
  path->advance(kDt, pose, false);
  EXPECT_EQ(path->motion(), MotionState::pausing);
  for (int k = 0; k < 200; ++k)
    path->advance(kDt, pose, false);
  EXPECT_EQ(path->motion(), MotionState::paused);
  EXPECT_EQ(path->velocity(), 0.0);
  const double held = pose[0];
  EXPECT_LT(held, 50.0);
  EXPECT_GT(path->distance_to_go(), 0.0);
  path->advance(kDt, pose, false);
  EXPECT_EQ(pose[0], held);
  path->resume();
  run(*path, pose);
  EXPECT_DOUBLE_EQ(pose[0], 50.0);
  EXPECT_EQ(path->motion(), MotionState::idle);
}

TEST(PathExecutor, AbortStopsUnderControlAndDropsTheQueue) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  ASSERT_NO_FATAL_FAILURE(push_two_lines(*path, 50, 100));
  for (int k = 0; k < 150; ++k)
    path->advance(kDt, pose, false);
  path->abort();
  path->advance(kDt, pose, false);
  EXPECT_EQ(path->motion(), MotionState::stopping);
  const PathRun r = run(*path, pose);
  EXPECT_EQ(path->motion(), MotionState::idle);
  EXPECT_FALSE(path->pending());
  EXPECT_EQ(path->segments_done(), 2u);  // dropped ones count as done
  EXPECT_LT(pose[0], 50.0);
  for (std::size_t k = 1; k < r.velocity.size(); ++k)
    EXPECT_LE(r.velocity[k - 1] - r.velocity[k], 1000 * kDt + 1e-9) << k;
}

TEST(PathExecutor, AbortWhileIdleLeavesLaterMovesAlone) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  path->abort();
  ASSERT_TRUE(path->segments().push(line(at(0), at(5))));
  run(*path, pose);
  EXPECT_DOUBLE_EQ(pose[0], 5.0);
}

TEST(PathExecutor, DwellWaitsItsTime) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  Segment dwell;
  dwell.kind = Segment::Kind::dwell;
  dwell.dwell_s = 0.25;
  ASSERT_TRUE(path->segments().push(dwell));
  const PathRun r = run(*path, pose);
  EXPECT_NEAR(r.periods, 250, 1);
  EXPECT_EQ(path->segments_done(), 1u);
  EXPECT_EQ(pose, AxisPose{});
}

TEST(PathExecutor, MoveNotStartingAtThePoseFaultsAndIsDropped) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose = at(1);
  ASSERT_TRUE(path->segments().push(line(at(0), at(5))));
  const PathExecutor::Result r = path->advance(kDt, pose, false);
  EXPECT_EQ(r.fault, PathExecutor::Fault::off_path);
  EXPECT_FALSE(r.moved);
  EXPECT_FALSE(path->pending());
  EXPECT_EQ(path->segments_done(), 1u);
  EXPECT_EQ(pose, at(1));
  EXPECT_EQ(path->motion(), MotionState::idle);
}

TEST(PathExecutor, JointsApartFaultOnlyWhenAMoveStartsFromRest) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  EXPECT_EQ(path->advance(kDt, pose, true).fault, PathExecutor::Fault::none);  // nothing to run
  ASSERT_TRUE(path->segments().push(line(at(0), at(5))));
  const PathExecutor::Result r = path->advance(kDt, pose, true);
  EXPECT_EQ(r.fault, PathExecutor::Fault::joints_apart);
  EXPECT_FALSE(path->pending());
  EXPECT_EQ(pose, AxisPose{});
}

TEST(PathExecutor, FlushDropsEverythingAtOnce) {
  const auto config = test::small_mill();
  auto path = make(config);
  AxisPose pose{};
  Segment s = line(at(0), at(50));
  s.moves = 3;  // folded zero-length moves count with it
  ASSERT_TRUE(path->segments().push(s));
  ASSERT_TRUE(path->segments().push(line(at(50), at(60))));
  for (int k = 0; k < 10; ++k)
    path->advance(kDt, pose, false);
  path->flush();
  EXPECT_FALSE(path->pending());
  EXPECT_FALSE(path->active());
  EXPECT_EQ(path->segments_done(), 2u);
  EXPECT_EQ(path->moves_done(), 4u);
}

TEST(PathExecutor, SCurveLimitsTheJerk) {
  auto config = test::small_mill();
  config.scurve = true;
  config.max_linear_jerk = 50'000;
  auto path = make(config);
  ASSERT_EQ(path->jerk(), 50'000);
  AxisPose pose{};
  ASSERT_TRUE(path->segments().push(line(at(0), at(30))));
  const PathRun r = run(*path, pose);
  EXPECT_NEAR(pose[0], 30.0, 1e-9);
  std::vector<double> accel;
  for (std::size_t k = 1; k < r.velocity.size(); ++k)
    accel.push_back((r.velocity[k] - r.velocity[k - 1]) / kDt);
  for (std::size_t k = 1; k < accel.size(); ++k)
    EXPECT_LE(std::abs(accel[k] - accel[k - 1]), 50'000 * kDt * 1.01) << k;
  // Slower than the trapezoid: the acceleration takes 20 ms to build up at each end.
  EXPECT_GT(r.periods, 300);
}

TEST(PathExecutor, SteepJerkFallsBackToTrapezoids) {
  auto config = test::small_mill();
  config.scurve = true;
  // 1000 mm/s^2 (Z) reached within fewer than 20 periods.
  config.max_linear_jerk = 1e6;
  EXPECT_EQ(make(config)->jerk(), 0.0);
}

}  // namespace
}  // namespace cncd::motion

namespace cncd::motion {
namespace {

// Calls check(path, pose, ratio) for each feed override ratio from 5 % to 99 % on a path 130
// periods into a long line, 97 periods after its override was lowered to that ratio.
template <typename Check>
void for_each_slowed_path(Check check) {
  const auto config = test::small_mill();
  for (int percent = 5; percent < 100; ++percent) {
    const double ratio = percent / 100.0;
    auto path = make(config);
    AxisPose pose{};
    ASSERT_TRUE(path->segments().push(line(at(0), at(137.3, 11.9), 97.1)));
    for (int k = 0; k < 130; ++k)
      path->advance(kDt, pose, false);
    path->set_overrides(ratio, 1.0);
    for (int k = 0; k < 97; ++k)
      path->advance(kDt, pose, false);
    check(*path, pose, ratio);
  }
}

// A lowered limit brakes to the new speed within a period's arithmetic: what is left over
// must not keep the path "moving" at a speed of 1e-16 forever, never paused, never aborted.
TEST(PathExecutor, LoweredOverrideThenAbortComesToRest) {
  for_each_slowed_path([](PathExecutor& path, AxisPose& pose, double ratio) {
    path.abort();
    const PathRun r = run(path, pose, 2000);
    EXPECT_LT(r.periods, 2000) << "override " << ratio;
    EXPECT_EQ(path.motion(), MotionState::idle) << "override " << ratio;
    EXPECT_FALSE(path.pending()) << "override " << ratio;
  });
}

TEST(PathExecutor, LoweredOverrideThenPauseHolds) {
  for_each_slowed_path([](PathExecutor& path, AxisPose& pose, double ratio) {
    path.pause();
    for (int k = 0; k < 300; ++k)
      path.advance(kDt, pose, false);
    EXPECT_EQ(path.motion(), MotionState::paused) << "override " << ratio;
    EXPECT_EQ(path.velocity(), 0.0) << "override " << ratio;
  });
}

}  // namespace
}  // namespace cncd::motion
