#include "cncd/drivers/spindle_position.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::drivers {
namespace {

constexpr double kNsPerS = 1e9;
// An answer is slow when it took more than twice the usual time and this much more.
constexpr std::int64_t kSlackNs = 500'000;
// After this many slow answers in a row, the drive is slow now: the next one is taken.
constexpr int kMaxDoubtful = 3;
// The filter's gains, critically damped with a smoothing of kTheta per reading: 0 takes each
// reading as it is, 1 never moves. At 0.5 a reading taken 0.5 ms off its time moves the
// estimate half as far as the three latest readings' exact fit would.
constexpr double kTheta = 0.5;
constexpr double kAlpha = 1 - kTheta * kTheta * kTheta;
constexpr double kBeta = 1.5 * (1 - kTheta * kTheta) * (1 - kTheta);
constexpr double kGamma = 0.5 * (1 - kTheta) * (1 - kTheta) * (1 - kTheta);

// `value` as a signed number of `width` bits.
std::int64_t sign_extend(std::uint64_t value, int width) {
  const std::uint64_t modulus = std::uint64_t{1} << width;
  value &= modulus - 1;
  return value >= modulus / 2
             ? static_cast<std::int64_t>(value) - static_cast<std::int64_t>(modulus)
             : static_cast<std::int64_t>(value);
}

}  // namespace

double SpindlePositionFit::at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept {
  const std::int64_t since = std::min(now_ns - time_ns, horizon_ns);
  const double dt = static_cast<double>(since) / kNsPerS;
  double fading = 0;
  if (blend_ns > 0 && since < blend_ns) {
    fading = correction * (1.0 - static_cast<double>(std::max<std::int64_t>(0, since)) /
                                     static_cast<double>(blend_ns));
  }
  return revolutions + rps * dt + 0.5 * acceleration * dt * dt + fading;
}

double SpindlePositionFit::rps_at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept {
  const double dt = static_cast<double>(std::min(now_ns - time_ns, horizon_ns)) / kNsPerS;
  return rps + acceleration * dt;
}

void SpindlePositionTracker::configure(int width, double counts_per_rev, double max_acceleration,
                                       std::int64_t gap_ns) noexcept {
  width_ = width == 16 ? 16 : 32;
  counts_per_rev_ = counts_per_rev != 0 && std::isfinite(counts_per_rev) ? counts_per_rev : 1.0;
  max_acceleration_ = std::isfinite(max_acceleration) ? std::max(0.0, max_acceleration) : 0.0;
  gap_ns_ = std::max<std::int64_t>(1, gap_ns);
  count_ = 0;
  readings_ = 0;
  typical_window_ns_ = -1;
  doubtful_ = 0;
  fit_ = {};
}

const SpindlePositionFit& SpindlePositionTracker::add(std::uint32_t raw, std::int64_t earliest_ns,
                                                      std::int64_t latest_ns) noexcept {
  // How long the drive took to answer, against how long it usually takes: a slow answer says
  // the request or the answer waited somewhere, so when the drive read its counter is unknown.
  const std::int64_t window = std::max<std::int64_t>(0, latest_ns - earliest_ns);
  if (typical_window_ns_ < 0) typical_window_ns_ = window;
  const bool doubtful = window > 2 * typical_window_ns_ + kSlackNs && doubtful_ < kMaxDoubtful;
  typical_window_ns_ += (window - typical_window_ns_) / 16;
  doubtful_ = doubtful ? doubtful_ + 1 : 0;
  const std::int64_t time_ns = earliest_ns + std::min(window, typical_window_ns_) / 2;

  if (!fit_.valid) {
    count_ = sign_extend(raw, width_);
    fit_.valid = true;
    fit_.revolutions = static_cast<double>(count_) / counts_per_rev_;
    fit_.time_ns = time_ns;
    readings_ = 1;
    return fit_;
  }
  const std::int64_t dt_ns = time_ns - fit_.time_ns;
  const bool gap = dt_ns > gap_ns_;
  // Where the spindle should be by now: over an ordinary update the filter's prediction;
  // across a gap (the bus was down) its speed alone. The reading is the count nearest to it
  // that the register's value allows.
  const double dt = static_cast<double>(dt_ns) / kNsPerS;
  const double predicted =
      gap ? fit_.revolutions + fit_.rps * dt
          : fit_.revolutions + fit_.rps * dt + 0.5 * fit_.acceleration * dt * dt;
  const double limit = 0x1p60;
  const auto expected =
      static_cast<std::int64_t>(std::clamp(std::round(predicted * counts_per_rev_), -limit, limit));
  count_ = expected + sign_extend(raw - static_cast<std::uint64_t>(expected), width_);
  // A doubtful reading is counted, not filtered: the prediction carries on to the next one. So
  // is one no later than the last (a clock that cannot tell them apart).
  if ((doubtful && !gap) || dt_ns <= 0) return fit_;

  const double reading = static_cast<double>(count_) / counts_per_rev_;
  const double shown = fit_.at(time_ns, gap_ns_);  // what the servo thread is being shown
  SpindlePositionFit next = fit_;
  next.time_ns = time_ns;
  if (gap || readings_ < 2) {
    // The filter (re)starts at the mean speed since the last reading.
    next.rps = (reading - fit_.revolutions) / dt;
    next.acceleration = 0;
    next.revolutions = reading;
    readings_ = 2;
  } else {
    const double p = predicted;
    const double v = fit_.rps + fit_.acceleration * dt;
    const double residual = reading - p;
    next.revolutions = p + kAlpha * residual;
    next.rps = v + kBeta * residual / dt;
    next.acceleration = fit_.acceleration + 2.0 * kGamma * residual / (dt * dt);
    if (max_acceleration_ > 0) {
      next.acceleration =
          std::clamp(next.acceleration, -2.0 * max_acceleration_, 2.0 * max_acceleration_);
    }
  }
  // The step from what was shown to the new estimate is spread over the time to the next
  // reading (about the last interval); after a gap there is nothing smooth to keep to.
  next.correction = gap ? 0.0 : shown - next.revolutions;
  next.blend_ns = gap ? 0 : dt_ns;
  fit_ = next;
  return fit_;
}

}  // namespace cncd::drivers
