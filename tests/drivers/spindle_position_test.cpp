// The position of a spindle read from a counter register now and then: unwrapping, and the
// position predicted between readings.
#include "cncd/drivers/spindle_position.hpp"

#include <cmath>
#include <cstdint>
#include <functional>

#include <gtest/gtest.h>

namespace cncd::test {
namespace {

using drivers::SpindlePositionTracker;

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kHorizon = 100 * kMs;

// What a counter of `width` bits shows at `revolutions`, `cpr` counts a revolution.
std::uint32_t reading(double revolutions, double cpr, int width) {
  const auto counts = static_cast<std::int64_t>(std::floor(revolutions * cpr));
  const std::uint64_t mask = (std::uint64_t{1} << width) - 1;
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(counts) & mask);
}

// Reads `truth` every `period` for `duration`, starting at 1 s; each reading's count must be
// the true one.
void expect_unwrapped(SpindlePositionTracker& tracker, const std::function<double(double)>& truth,
                      double cpr, int width, std::int64_t period, double duration) {
  for (std::int64_t t = 1000 * kMs; t <= 1000 * kMs + duration * 1e9; t += period) {
    const double rev = truth(static_cast<double>(t) / 1e9);
    tracker.add(reading(rev, cpr, width), t);
    ASSERT_EQ(tracker.counts(), static_cast<std::int64_t>(std::floor(rev * cpr)))
        << "at " << t / kMs << " ms";
  }
}

TEST(SpindlePosition, A16BitCounterIsUnwrappedForwardAndInReverse) {
  SpindlePositionTracker tracker;
  tracker.configure(16, 4096, 0, 50 * kMs);
  // 10 rev/s forward: the counter wraps every 1.6 s.
  expect_unwrapped(
      tracker, [](double t) { return 10 * (t - 1); }, 4096, 16, 5 * kMs, 4);
  SpindlePositionTracker reverse;
  reverse.configure(16, 4096, 0, 50 * kMs);
  expect_unwrapped(
      reverse, [](double t) { return -10 * (t - 1); }, 4096, 16, 5 * kMs, 4);
  EXPECT_LT(reverse.fit().revolutions, -39.9);
}

TEST(SpindlePosition, AFastSpindleIsUnwrappedFromItsSpeed) {
  // 300 rev/s at 16384 counts a revolution, read every 10 ms: 49152 counts between readings,
  // more than half the 16-bit counter's range. The count is taken nearest to where the speed
  // predicts it; from the counter alone it would be read as going backwards.
  SpindlePositionTracker tracker;
  tracker.configure(16, 16384, 0, 50 * kMs);
  const auto truth = [](double t) {
    const double s = t - 1;  // 0 .. 0.2 s: up to speed at 1500 rev/s^2, then steady
    return s < 0.2 ? 750 * s * s : 30 + 300 * (s - 0.2);
  };
  expect_unwrapped(tracker, truth, 16384, 16, 10 * kMs, 1);
  EXPECT_NEAR(tracker.fit().rps, 300, 1);
}

TEST(SpindlePosition, ANegativeScaleCountsDownTurningForward) {
  SpindlePositionTracker tracker;
  tracker.configure(32, -1000, 0, 50 * kMs);
  for (int k = 0; k <= 100; ++k) {
    const double rev = 0.1 * k;  // 10 rev/s, every 10 ms
    tracker.add(reading(-rev, 1000, 32), 1000 * kMs + k * 10 * kMs);
  }
  EXPECT_NEAR(tracker.fit().revolutions, 10, 1e-3);
  EXPECT_NEAR(tracker.fit().rps, 10, 0.05);
}

TEST(SpindlePosition, TheFirstReadingIsTakenAsASignedCount) {
  SpindlePositionTracker tracker;
  tracker.configure(32, 100, 0, 50 * kMs);
  tracker.add(0xFFFFFFFEu, 5 * kMs);
  EXPECT_EQ(tracker.counts(), -2);
  EXPECT_DOUBLE_EQ(tracker.fit().revolutions, -0.02);
  EXPECT_EQ(tracker.fit().rps, 0);
}

TEST(SpindlePosition, BetweenReadingsThePositionIsPredicted) {
  // A spindle ramping from rest at 50 rev/s^2 (3000 rpm/s), read every 10 ms with 4096 counts
  // a revolution. The last reading itself falls up to 0.2 revolutions behind; the prediction
  // stays within a hundredth of a revolution while the filter learns the ramp, and within a
  // few counts once it has.
  SpindlePositionTracker tracker;
  tracker.configure(32, 4096, 50, 50 * kMs);
  const auto truth = [](double t) { return 25 * t * t; };  // from rest at t = 0
  double worst_learning = 0;
  double worst_settled = 0;
  double worst_reading = 0;
  for (std::int64_t t = 0; t <= 400 * kMs; t += kMs) {
    const double now = static_cast<double>(t) / 1e9;
    if (t % (10 * kMs) == 0) tracker.add(reading(truth(now), 4096, 32), t);
    const double error = std::abs(tracker.fit().at(t, kHorizon) - truth(now));
    double& worst = t < 200 * kMs ? worst_learning : worst_settled;
    worst = std::max(worst, error);
    worst_reading = std::max(worst_reading, std::abs(tracker.fit().revolutions - truth(now)));
    if (t >= 200 * kMs) {
      EXPECT_NEAR(tracker.fit().rps_at(t, kHorizon), 50 * now, 0.05);
    }
  }
  EXPECT_LE(worst_learning, 0.01);
  EXPECT_LE(worst_settled, 3.0 / 4096);
  EXPECT_GE(worst_reading, 0.15);  // 20 rev/s x 9 ms, near the end
}

TEST(SpindlePosition, JitterInWhenTheDriveReadsIsSmoothedAndNeverJumps) {
  // 10 rev/s, read every 5 ms, each reading taken up to 0.5 ms before or after its stamp:
  // 0.005 revolutions either way, and the newest reading up to 0.05 behind. The estimate keeps
  // within about twice the jitter, and each servo period (1 ms) it moves with the spindle (0.01
  // revolutions) give or take less than the jitter: the fit through the three latest readings
  // it replaced let it step 0.017.
  SpindlePositionTracker tracker;
  tracker.configure(32, 4096, 50, 50 * kMs);
  std::uint32_t seed = 12345;
  const auto jitter_ns = [&] {  // a fixed pseudo-random sequence, -0.5 .. 0.5 ms
    seed = seed * 1103515245u + 12345u;
    return static_cast<std::int64_t>((seed >> 16) % 1001) * 1000 - 500'000;
  };
  double worst = 0;
  double worst_step = 0;
  double last = 0;
  for (std::int64_t t = 0; t <= 1000 * kMs; t += kMs) {
    if (t % (5 * kMs) == 0) {
      const double taken = static_cast<double>(t + jitter_ns()) / 1e9;
      tracker.add(reading(10 * taken, 4096, 32), t);
    }
    const double estimate = tracker.fit().at(t, kHorizon);
    if (t >= 100 * kMs) {
      worst = std::max(worst, std::abs(estimate - 10 * static_cast<double>(t) / 1e9));
      worst_step = std::max(worst_step, std::abs(estimate - last - 0.01));
    }
    last = estimate;
  }
  EXPECT_LE(worst, 0.012);
  EXPECT_LE(worst_step, 0.005);
}

TEST(SpindlePosition, ThePredictionStopsAtTheHorizon) {
  SpindlePositionTracker tracker;
  tracker.configure(32, 1000, 0, 50 * kMs);
  tracker.add(0, 0);
  tracker.add(100, 10 * kMs);  // 10 rev/s
  EXPECT_NEAR(tracker.fit().at(30 * kMs, kHorizon), 0.3, 1e-9);
  EXPECT_NEAR(tracker.fit().at(10'000 * kMs, kHorizon), 1.1, 1e-9);
}

TEST(SpindlePosition, AfterAGapTheCountCarriesOnFromTheSpeed) {
  // The bus was down for 300 ms at 10 rev/s: 3 revolutions, 49152 counts at 16384 a
  // revolution, three quarters of the 16-bit counter's range. The speed before the gap says
  // which way round the counter went.
  SpindlePositionTracker tracker;
  tracker.configure(16, 16384, 50, 50 * kMs);
  const auto truth = [](double t) { return 10 * t; };
  for (std::int64_t t = 0; t <= 100 * kMs; t += 10 * kMs)
    tracker.add(reading(truth(static_cast<double>(t) / 1e9), 16384, 16), t);
  const std::int64_t later = 400 * kMs;
  tracker.add(reading(truth(0.4), 16384, 16), later);
  EXPECT_EQ(tracker.counts(), 4 * 16384);
  // The filter starts afresh at the mean speed across the gap.
  EXPECT_NEAR(tracker.fit().rps, 10, 0.01);
  EXPECT_NEAR(tracker.fit().at(later + 10 * kMs, kHorizon), 4.1, 0.001);
}

TEST(SpindlePosition, TheAccelerationIsHeldWithinTwiceTheSpindles) {
  SpindlePositionTracker tracker;
  tracker.configure(32, 1000, 10, 50 * kMs);
  tracker.add(0, 0);
  tracker.add(0, 10 * kMs);
  tracker.add(100, 20 * kMs);  // 0 to 10 rev/s in 10 ms: 1000 rev/s^2 at face value
  EXPECT_DOUBLE_EQ(tracker.fit().acceleration, 20);
}

}  // namespace
}  // namespace cncd::test
