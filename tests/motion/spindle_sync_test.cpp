// Motion in step with the spindle, in the servo loop in virtual time: rigid taps (G33.1) and
// threads (G33) on the simulated spindle with its ACCELERATION ramp, the ideal spindle, the
// feed override, a feed hold, an abort, feed per revolution and constant surface speed.
//
// The helix error of a period is the axis's command of that period against the spindle's
// position one period later, when the axis has got there: the sim spindle integrates its speed
// on its own, so the error is measured, not assumed.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "spindle_sync_fixture.hpp"

namespace cncd::test {
namespace {

using namespace spindle_sync;

TEST_F(SpindleSyncTest, RigidTapStaysOnTheHelixThroughTheReversalAndReturns) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  run(20000, true);
  ASSERT_EQ(machine_->status().motion, MotionState::idle);
  EXPECT_EQ(machine_->status().path_errors, 0u);
  // The spindle came to rest, then the tap locked to it.
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  ASSERT_LT(in, samples_.size());
  EXPECT_GT(in, 0u);
  EXPECT_EQ(samples_[in - 1].phase, SyncStatus::Phase::spindle_stopping);
  EXPECT_LT(samples_[in].rpm, 1.0);
  const std::size_t out = first(SyncStatus::Phase::tapping_out, in);
  const std::size_t end = first(SyncStatus::Phase::none, out);
  ASSERT_LT(end, samples_.size());
  // The whole tap on the helix, well within pitch x 0.02.
  const double error = helix_error(0, kPitch, 1, in, end);
  EXPECT_LE(error, kPitch * 0.02);
  EXPECT_LE(error, 0.002) << "the helix error is meant to be far below the limit";
  // Down to the bottom, and back where it started.
  double deepest = 0;
  for (const Sample& s : samples_)
    deepest = std::min(deepest, s.z);
  EXPECT_NEAR(deepest, -10, 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  // The spindle reversed at the bottom (its position ran back), at full speed both ways.
  double max_rev = -1e300;
  std::size_t bottom = 0;
  for (std::size_t k = in; k < end; ++k) {
    if (samples_[k].revolutions > max_rev) {
      max_rev = samples_[k].revolutions;
      bottom = k;
    }
  }
  EXPECT_NEAR(max_rev - samples_[in].revolutions, 10 / kPitch, 0.01);
  EXPECT_NEAR(samples_[end].revolutions, samples_[in].revolutions, 0.002);
  double fastest_in = 0, fastest_out = 0;
  for (std::size_t k = in; k < end; ++k)
    (k < bottom ? fastest_in : fastest_out) =
        std::max(k < bottom ? fastest_in : fastest_out, samples_[k].rpm);
  EXPECT_NEAR(fastest_in, 600, 1);
  EXPECT_NEAR(fastest_out, 600, 1);
  // Within the axes' limits, and the spindle turns forward again at 600 rpm.
  expect_within_limits(*machine_, {0, 0, 0});
  EXPECT_EQ(machine_->status().spindle.direction, 1);
  run(1000);
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 600, 1e-6);
  EXPECT_GT(samples_.back().revolutions, samples_[end].revolutions + 1);
  EXPECT_EQ(machine_->status().sync.done, 1u);
}

TEST_F(SpindleSyncTest, LeftHandTapTurnsTheOtherWay) {
  start(mill_with_sim_spindle(3000), 600, -1);
  machine_->queue(synced(SpindleSync::tap, -5));
  run(20000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, -1, in, end), 0.002);
  double lowest = 1e300;
  for (std::size_t k = in; k < end; ++k)
    lowest = std::min(lowest, samples_[k].revolutions);
  EXPECT_NEAR(samples_[in].revolutions - lowest, 5 / kPitch, 0.01);
  EXPECT_EQ(machine_->status().spindle.direction, -1);
}

TEST_F(SpindleSyncTest, TheIdealSpindleTapsAlongItsCommand) {
  config::MachineConfig c = small_mill();  // no [SPINDLE_0]: at any speed at once
  start(c);
  machine_->queue(synced(SpindleSync::tap, -10));
  run(20000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, 1, in, end), 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  // Z's acceleration is the ramp's limit: the tap stays within it.
  expect_within_limits(*machine_, {0, 0, 0});
}

TEST_F(SpindleSyncTest, FeedOverrideScalesSpindleAndAxisTogether) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -40));
  run(700);  // well into the hole at full speed
  const Sample full = samples_.back();
  ASSERT_EQ(full.phase, SyncStatus::Phase::tapping_in);
  ASSERT_NEAR(full.rpm, 600, 1e-6);
  const double z_before = samples_[samples_.size() - 11].z;
  const double full_rate = (z_before - full.z) / (10 * machine_->period_s());
  EXPECT_NEAR(full_rate, 600 / 60.0 * kPitch, 0.01);

  send({Command::Kind::feed_override, 0, 0, 0.5});
  run(300);
  const Sample half = samples_.back();
  ASSERT_EQ(half.phase, SyncStatus::Phase::tapping_in);
  EXPECT_NEAR(half.rpm, 300, 1e-6);
  const double half_rate =
      (samples_[samples_.size() - 11].z - half.z) / (10 * machine_->period_s());
  EXPECT_NEAR(half_rate, full_rate / 2, 0.01);
  run(40000, true);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t end = first(SyncStatus::Phase::none, in);
  ASSERT_LT(end, samples_.size());
  EXPECT_LE(helix_error(0, kPitch, 1, in, end), 0.002);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
}

TEST_F(SpindleSyncTest, FeedHoldLetsTheTapComeBackOut) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  machine_->queue(line_to(Move::Kind::feed, 5, 0, 0, 10));
  run(400);
  ASSERT_EQ(samples_.back().phase, SyncStatus::Phase::tapping_in);
  send({Command::Kind::pause});
  run(5000);
  // Out of the hole, at rest where the tap started, and held there.
  EXPECT_EQ(machine_->status().motion, MotionState::paused);
  EXPECT_NEAR(machine_->status().commanded[2], 0, 1e-9);
  EXPECT_NEAR(machine_->status().commanded[0], 0, 1e-12);
  double deepest = 0;
  for (const Sample& s : samples_)
    deepest = std::min(deepest, s.z);
  EXPECT_NEAR(deepest, -10, 0.002);
  const std::size_t end = first(SyncStatus::Phase::none, first(SyncStatus::Phase::tapping_in));
  ASSERT_LT(end, samples_.size());
  for (std::size_t k = 0; k < end; ++k)
    ASSERT_NE(samples_[k].motion, MotionState::paused) << "paused in the hole at " << k;
  EXPECT_EQ(samples_[end].motion, MotionState::paused);
  send({Command::Kind::resume});
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[0], 5, 1e-9);
}

TEST_F(SpindleSyncTest, AbortStopsSpindleAndAxisTogetherInTheHole) {
  start(mill_with_sim_spindle(3000));
  machine_->queue(synced(SpindleSync::tap, -10));
  run(400);
  ASSERT_EQ(samples_.back().phase, SyncStatus::Phase::tapping_in);
  const std::size_t in = first(SyncStatus::Phase::tapping_in);
  const std::size_t aborted = samples_.size();
  send({Command::Kind::abort});
  run(3000, true);
  EXPECT_EQ(machine_->status().motion, MotionState::idle);
  EXPECT_EQ(machine_->status().spindle.direction, 0);
  EXPECT_LT(machine_->status().spindle.actual_rpm, 1e-9);
  // It stopped in the hole, still on the helix, and within the axes' limits.
  const double z = machine_->status().commanded[2];
  EXPECT_LT(z, samples_[aborted - 1].z);
  EXPECT_GT(z, -10);
  EXPECT_LE(helix_error(0, kPitch, 1, in, samples_.size() - 1), 0.002);
  expect_within_limits(*machine_, {0, 0, 0});
}

TEST_F(SpindleSyncTest, ThreadStartsAtTheIndexAndFollowsTheHelix) {
  start(mill_with_sim_spindle(3000));
  const double at_start = machine_->status().spindle.revolutions;
  machine_->queue(synced(SpindleSync::thread, -30, 1.5));
  run(20000, true);
  EXPECT_EQ(machine_->status().path_errors, 0u);
  EXPECT_NEAR(machine_->status().commanded[2], -30, 1e-9);
  // Nothing moves before the next whole revolution.
  const double index = std::ceil(at_start);
  for (const Sample& s : samples_) {
    if (s.revolutions < index - 0.02) {
      EXPECT_EQ(s.z, 0);
    }
  }
  // Once caught up (within a few revolutions), on the helix from the index until the line's
  // end slows it.
  double worst = 0;
  for (std::size_t k = 0; k + 1 < samples_.size(); ++k) {
    const double z_ideal = -1.5 * (samples_[k + 1].revolutions - index);
    if (samples_[k + 1].revolutions < index + 2 || z_ideal < -28) continue;
    worst = std::max(worst, std::abs(samples_[k].z - z_ideal));
  }
  EXPECT_LE(worst, 1.5 * 0.02);
  expect_within_limits(*machine_, {0, 0, 0});
  // The spindle was left alone.
  EXPECT_EQ(machine_->status().spindle.direction, 1);
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 600, 1e-9);
}

// The largest distance from the helix z = -pitch x (revolutions - index), over the samples
// from `from` on where the helix is above `bottom`, two revolutions past `settled` and away
// from (more than 1.5 revolutions after) the revolution `corner`.
double off_helix(const std::vector<Sample>& samples, double index, double pitch, double settled,
                 double corner, double bottom) {
  double worst = 0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
    const double rev = samples[k + 1].revolutions;
    const double z_ideal = -pitch * (rev - index);
    if (rev < settled + 2 || (rev > corner - 0.5 && rev < corner + 1.5) || z_ideal < bottom)
      continue;
    worst = std::max(worst, std::abs(samples[k].z - z_ideal));
  }
  return worst;
}

// G33 Z-10.3 then G33 Z-20: the second move goes on along the first one's helix (a taper after
// the straight part of a thread, a chain of G33 moves), not from the next index: 10.3 mm is not
// a whole number of pitches, and a new index would shift its helix by 0.2 mm.
TEST_F(SpindleSyncTest, AThreadMoveAfterAnotherGoesOnAlongItsHelix) {
  start(mill_with_sim_spindle(3000));
  const double index = std::ceil(machine_->status().spindle.revolutions);
  machine_->queue(synced(SpindleSync::thread, -10.3, 1.5));
  machine_->queue(synced(SpindleSync::thread, -20, 1.5));
  run(20000, true);
  EXPECT_EQ(machine_->status().path_errors, 0u);
  EXPECT_NEAR(machine_->status().commanded[2], -20, 1e-9);
  const double corner = index + 10.3 / 1.5;
  EXPECT_LE(off_helix(samples_, index, 1.5, index, corner, -18.5), 1.5 * 0.02);
  // The second move's part checked: from 1.5 revolutions past the corner to 1.5 mm short of
  // its end, two and a half revolutions.
  expect_within_limits(*machine_, {0, 0, 0});
}

// A hold between the two: the second waits for the spindle to come round to its helix again.
TEST_F(SpindleSyncTest, AHoldBetweenTwoThreadMovesKeepsTheHelix) {
  start(mill_with_sim_spindle(3000));
  const double index = std::ceil(machine_->status().spindle.revolutions);
  machine_->queue(synced(SpindleSync::thread, -10.3, 1.5));
  machine_->queue(synced(SpindleSync::thread, -20, 1.5));
  run(100);
  ASSERT_EQ(machine_->status().sync.phase, SyncStatus::Phase::following);
  send({Command::Kind::pause});
  run(2000);
  // The first ran to its end and the second held before it, while the spindle turned on.
  EXPECT_NEAR(machine_->status().commanded[2], -10.3, 1e-9);
  EXPECT_EQ(machine_->status().motion, MotionState::paused);
  const double resumed = machine_->status().spindle.revolutions;
  EXPECT_GT(resumed, index + 10.3 / 1.5 + 5);
  send({Command::Kind::resume});
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[2], -20, 1e-9);
  // Nothing moves before the spindle reaches the helix's phase again, then on it.
  const double next = index + 10.3 / 1.5 + std::ceil(resumed - index - 10.3 / 1.5);
  for (const Sample& s : samples_) {
    if (s.revolutions > resumed && s.revolutions < next - 0.02) {
      EXPECT_NEAR(s.z, -10.3, 1e-9);
    }
  }
  EXPECT_LE(off_helix(samples_, index, 1.5, next, next, -18.5), 1.5 * 0.02);
  expect_within_limits(*machine_, {0, 0, 0});
}

// The signed speed a spindle command asks for, rev/s (forward > 0).

TEST_F(SpindleSyncTest, AFeedHoldBeforeAThreadStartsHoldsBeforeIt) {
  start(mill_with_sim_spindle(3000));
  // The hold is there before the thread's first period: the thread does not start.
  machine_->queue(synced(SpindleSync::thread, -30, 1.5));
  ASSERT_TRUE(machine_->loop().commands().push({Command::Kind::pause}));
  run(2000);
  for (std::size_t k = 0; k < samples_.size(); ++k) {
    ASSERT_EQ(samples_[k].z, 0) << "moved in period " << k;
    ASSERT_EQ(samples_[k].phase, SyncStatus::Phase::none) << "started in period " << k;
  }
  EXPECT_EQ(machine_->status().motion, MotionState::paused);
  send({Command::Kind::resume});
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[2], -30, 1e-9);
  EXPECT_EQ(machine_->status().path_errors, 0u);
}

TEST_F(SpindleSyncTest, FeedPerRevolutionFollowsTheSpindlesActualSpeed) {
  start(mill_with_sim_spindle(3000));
  Move cut = line_to(Move::Kind::feed, 50, 0, 0, 0.1 * 600 / 60.0);
  cut.feed_per_rev = 0.1;  // 1 mm/s at 600 rpm
  machine_->queue(cut);
  run(1000);
  const double x0 = machine_->status().commanded[0];
  run(100);
  EXPECT_NEAR((machine_->status().commanded[0] - x0) / 0.1, 1.0, 1e-6);
  send({Command::Kind::spindle_override, 0, 0, 0.5});
  run(400);  // the spindle ramps down to 300 rpm in 0.1 s
  EXPECT_NEAR(machine_->status().spindle.actual_rpm, 300, 1e-6);
  const double x1 = machine_->status().commanded[0];
  run(100);
  EXPECT_NEAR((machine_->status().commanded[0] - x1) / 0.1, 0.5, 1e-6);
}

// G96: the spindle turns at the surface speed over the tool's distance from X0, within D.
TEST_F(SpindleSyncTest, ConstantSurfaceSpeedFollowsX) {
  machine_ = std::make_unique<VirtualMachine>(mill_with_sim_spindle(60000));
  machine_->ready();
  machine_->queue(line_to(Move::Kind::traverse, 50, 0, 0));
  IoAction css;
  css.kind = IoAction::Kind::spindle;
  css.direction = 1;
  css.rpm = 100;                                            // m/min
  css.css_numerator = 100 * 1000 / (2 * 3.14159265358979);  // mm/min over 2 pi
  css.css_max_rpm = 2000;
  css.css_x_origin = 0;
  machine_->queue(action(css));
  machine_->queue(line_to(Move::Kind::feed, 1, 0, 0, 5));
  for (int i = 0; i < 5000 && machine_->status().spindle.direction == 0; ++i)
    run(1);
  ASSERT_EQ(machine_->status().commanded[0], 50);
  // At X50: 100 m/min / (2 pi 50 mm) = 318.3 rpm.
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 318.31, 0.01);
  // Half way in, twice as fast.
  for (int i = 0; i < 20000 && machine_->status().commanded[0] > 25; ++i)
    run(1);
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 100e3 / (2 * 3.14159265358979 * 25), 0.2);
  run(20000, true);
  EXPECT_NEAR(machine_->status().commanded[0], 1, 1e-9);
  // At X1 it would be 15,915 rpm: D caps it.
  EXPECT_NEAR(machine_->status().spindle.commanded_rpm, 2000, 1e-9);
}

}  // namespace
}  // namespace cncd::test
