// A seqlock for one writer and any number of readers: the writer never waits, readers retry
// until they copy a consistent snapshot.
//
// The payload is copied word by word through atomics, so there is no data race in the C++
// memory model, and ordered without standalone fences (which ThreadSanitizer cannot follow):
// every payload word is stored with release after the sequence turns odd, and loaded with
// acquire before the sequence is read again. A reader that sees any word of a newer write
// therefore also sees the newer sequence and retries. On x86 these are plain moves.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace cncd::motion {

template <typename T>
class Seqlock {
  static_assert(std::is_trivially_copyable_v<T>);
  static constexpr std::size_t kWords =
      (sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);

 public:
  // Writer thread only. RT-safe: never waits, never allocates.
  void store(const T& value) noexcept {
    std::uint64_t words[kWords] = {};
    std::memcpy(words, &value, sizeof(T));
    const std::uint64_t seq = seq_.load(std::memory_order_relaxed);
    seq_.store(seq + 1, std::memory_order_relaxed);
    for (std::size_t i = 0; i < kWords; ++i)
      data_[i].store(words[i], std::memory_order_release);
    seq_.store(seq + 2, std::memory_order_release);
  }
  // Any thread. Retries while a write is in progress (a write takes well under a microsecond).
  T load() const noexcept {
    std::uint64_t words[kWords];
    for (;;) {
      const std::uint64_t before = seq_.load(std::memory_order_acquire);
      if (before & 1) continue;
      for (std::size_t i = 0; i < kWords; ++i)
        words[i] = data_[i].load(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == before) break;
    }
    T value;
    std::memcpy(&value, words, sizeof(T));
    return value;
  }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::atomic<std::uint64_t> data_[kWords] = {};
};

}  // namespace cncd::motion
