// Wake-up error histogram of the servo loop: fixed memory, O(1) per sample, percentiles on
// demand. RT-safe.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "cncd/drivers/rt.hpp"

namespace cncd::motion {

class RtHistogram {
 public:
  // 1 µs buckets up to 1 ms, 100 µs buckets up to 100 ms, one overflow bucket.
  static constexpr int kFine = 1000;
  static constexpr int kCoarse = 990;
  static constexpr int kBuckets = kFine + kCoarse + 1;

  CNCD_RT void add(std::int64_t error_ns) noexcept;
  // Upper edge (ns) of the bucket holding the q-quantile, q in [0, 1].
  CNCD_RT std::int64_t quantile_ns(double q) const noexcept;
  CNCD_RT std::int64_t max_ns() const noexcept { return max_ns_; }
  std::uint64_t count() const noexcept { return count_; }
  // Sum of the errors counted (negative ones as 0), ns.
  std::uint64_t sum_ns() const noexcept { return sum_ns_; }
  // Fills below[i] with the number of errors under edges_us[i] microseconds (ascending edges,
  // each 1 to 1000 or a multiple of 100 up to 100000: the buckets' own edges). One pass.
  CNCD_RT void count_below(const std::int32_t* edges_us, std::uint64_t* below,
                           std::size_t n) const noexcept;

 private:
  // 64 bits: at a 1 kHz servo period a 32-bit bucket would wrap after 49 days.
  std::array<std::uint64_t, kBuckets> buckets_{};
  std::uint64_t count_ = 0;
  std::uint64_t sum_ns_ = 0;
  std::int64_t max_ns_ = 0;
};

}  // namespace cncd::motion
