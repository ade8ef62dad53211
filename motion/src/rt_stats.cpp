#include "cncd/motion/rt_stats.hpp"

#include <algorithm>

namespace cncd::motion {

void RtHistogram::add(std::int64_t error_ns) noexcept {
  if (error_ns < 0) error_ns = 0;
  if (error_ns > max_ns_) max_ns_ = error_ns;
  const std::int64_t us = error_ns / 1000;
  int bucket;
  if (us < kFine) {
    bucket = static_cast<int>(us);
  } else if (us < kFine + kCoarse * 100) {
    bucket = kFine + static_cast<int>((us - kFine) / 100);
  } else {
    bucket = kBuckets - 1;
  }
  ++buckets_[static_cast<std::size_t>(bucket)];
  ++count_;
  sum_ns_ += static_cast<std::uint64_t>(error_ns);
}

void RtHistogram::count_below(const std::int32_t* edges_us, std::uint64_t* below,
                              std::size_t n) const noexcept {
  std::uint64_t seen = 0;
  int bucket = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // The first bucket at or past the edge: fine buckets are 1 us wide from 0, coarse ones
    // 100 us wide from 1000 us.
    const std::int32_t edge = edges_us[i];
    const int end = edge <= kFine ? edge : std::min(kFine + (edge - kFine) / 100, kBuckets - 1);
    for (; bucket < end; ++bucket)
      seen += buckets_[static_cast<std::size_t>(bucket)];
    below[i] = seen;
  }
}

std::int64_t RtHistogram::quantile_ns(double q) const noexcept {
  if (count_ == 0) return 0;
  const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(count_ - 1)) + 1;
  std::uint64_t seen = 0;
  for (int b = 0; b < kBuckets; ++b) {
    seen += buckets_[static_cast<std::size_t>(b)];
    if (seen >= rank) {
      if (b < kFine) return (b + 1) * 1000LL;
      if (b < kBuckets - 1) return (kFine + (b - kFine + 1) * 100LL) * 1000LL;
      return max_ns_;
    }
  }
  return max_ns_;
}

}  // namespace cncd::motion
