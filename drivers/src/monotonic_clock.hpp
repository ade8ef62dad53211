// CLOCK_MONOTONIC in nanoseconds, the time base every driver thread shares. RT-safe.
#pragma once

#include <time.h>

#include <cstdint>

namespace cncd::drivers {

inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace cncd::drivers
