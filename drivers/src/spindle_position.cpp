#include "cncd/drivers/spindle_position.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::drivers {
namespace {

constexpr double kNsPerS = 1e9;

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
  const double dt = static_cast<double>(std::min(now_ns - time_ns, horizon_ns)) / kNsPerS;
  return revolutions + rps * dt + 0.5 * acceleration * dt * dt;
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
  readings_ = 0;
  count_ = 0;
  last_raw_ = 0;
  fit_ = {};
}

const SpindlePositionFit& SpindlePositionTracker::add(std::uint32_t raw,
                                                      std::int64_t time_ns) noexcept {
  const std::uint64_t modulus = std::uint64_t{1} << width_;
  if (readings_ == 0) {
    count_ = sign_extend(raw, width_);
  } else {
    // Where the spindle should be by now: over an ordinary update the fit's prediction; across
    // a gap (the bus was down) its speed alone. The reading is the count nearest to it that
    // the register's value allows.
    const std::int64_t dt_ns = time_ns - fit_.time_ns;
    const double predicted = dt_ns > gap_ns_ ? fit_.rps * (static_cast<double>(dt_ns) / kNsPerS)
                                             : fit_.at(time_ns, gap_ns_) - fit_.revolutions;
    const double limit = 0x1p60;
    const auto expected = static_cast<std::int64_t>(
        std::clamp(std::round(predicted * counts_per_rev_), -limit, limit));
    const std::uint64_t moved = (static_cast<std::uint64_t>(raw) - last_raw_) & (modulus - 1);
    const std::int64_t off = sign_extend(moved - static_cast<std::uint64_t>(expected), width_);
    count_ += expected + off;
    if (dt_ns > gap_ns_) readings_ = 0;  // the fit starts afresh; the count carries on
  }
  last_raw_ = raw;
  if (readings_ > 0 && time_ns <= history_[0].time_ns) {
    history_[0].counts = count_;  // no later than the newest: it replaces it
  } else {
    for (std::size_t i = history_.size() - 1; i > 0; --i)
      history_[i] = history_[i - 1];
    history_[0] = Reading{count_, time_ns};
    readings_ = std::min(readings_ + 1, static_cast<int>(history_.size()));
  }
  refit();
  return fit_;
}

void SpindlePositionTracker::refit() noexcept {
  const Reading& r0 = history_[0];
  fit_.valid = true;
  fit_.time_ns = r0.time_ns;
  fit_.revolutions = static_cast<double>(r0.counts) / counts_per_rev_;
  fit_.rps = 0;
  fit_.acceleration = 0;
  if (readings_ < 2) return;
  // Divided differences: the mean speed over each of the two latest intervals, and the change
  // between them; the speed at the newest reading follows from both.
  const auto rev = [&](const Reading& r) {
    return static_cast<double>(r.counts - r0.counts) / counts_per_rev_;
  };
  const auto seconds = [](std::int64_t ns) { return static_cast<double>(ns) / kNsPerS; };
  const double h1 = seconds(r0.time_ns - history_[1].time_ns);
  const double v1 = -rev(history_[1]) / h1;
  double a = 0;
  if (readings_ >= 3) {
    const double h2 = seconds(history_[1].time_ns - history_[2].time_ns);
    const double v2 = (rev(history_[1]) - rev(history_[2])) / h2;
    a = (v1 - v2) / (0.5 * (h1 + h2));
    if (max_acceleration_ > 0) a = std::clamp(a, -2.0 * max_acceleration_, 2.0 * max_acceleration_);
  }
  fit_.acceleration = a;
  fit_.rps = v1 + 0.5 * a * h1;
}

}  // namespace cncd::drivers
