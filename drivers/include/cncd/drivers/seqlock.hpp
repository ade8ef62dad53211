// A single-writer seqlock for small trivially copyable values: the writer never waits, readers
// retry while a write is in progress. The payload lives in atomic words, so a torn read is
// detected and discarded instead of being a data race.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>, "seqlock payloads are copied bytewise");

 public:
  // RT-safe; one writer thread only.
  CNCD_RT void store(const T& value) noexcept {
    std::array<std::uint64_t, kWords> buffer{};
    std::memcpy(buffer.data(), &value, sizeof(T));
    // The acquire read-modify-write keeps the payload stores after the odd count; the release
    // stores let a reader that sees any new word also see that count (no fences: they are
    // invisible to ThreadSanitizer).
    const std::uint64_t seq = seq_.fetch_add(1, std::memory_order_acquire);
    for (std::size_t i = 0; i < kWords; ++i)
      words_[i].store(buffer[i], std::memory_order_release);
    seq_.store(seq + 2, std::memory_order_release);
  }

  // RT-safe, any thread. False when a write overlapped; `out` is then unchanged.
  CNCD_RT bool try_load(T& out) const noexcept {
    const std::uint64_t before = seq_.load(std::memory_order_acquire);
    if ((before & 1u) != 0) return false;
    std::array<std::uint64_t, kWords> buffer{};
    for (std::size_t i = 0; i < kWords; ++i)
      buffer[i] = words_[i].load(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != before) return false;
    std::memcpy(static_cast<void*>(&out), buffer.data(), sizeof(T));
    return true;
  }

  // RT-safe, any thread. Retries until a consistent copy is read; the writer's critical section
  // is a few stores, so this ends quickly.
  CNCD_RT T load() const noexcept {
    T out{};
    while (!try_load(out)) {
    }
    return out;
  }

  // Number of completed stores; lets a reader see whether anything new arrived.
  CNCD_RT std::uint64_t version() const noexcept {
    return seq_.load(std::memory_order_acquire) / 2;
  }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace cncd::drivers
