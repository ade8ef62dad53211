// Lock-free single-producer single-consumer ring of trivially copyable elements.
// One thread pushes, one other thread pops; neither ever blocks. RT-safe on both sides.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

#include "cncd/drivers/rt.hpp"

namespace cncd::motion {

template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "ring elements are copied between threads");
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity: power of two");

 public:
  // Producer thread. False when full.
  CNCD_RT bool push(const T& value) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == Capacity) return false;
    slots_[head & (Capacity - 1)] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  // Consumer thread. False when empty.
  CNCD_RT bool pop(T& out) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  // Consumer thread: the oldest element without removing it, or nullptr.
  CNCD_RT const T* front() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return nullptr;
    return &slots_[tail & (Capacity - 1)];
  }
  // Any thread; exact only on the producer or consumer thread.
  CNCD_RT std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  static constexpr std::size_t capacity() noexcept { return Capacity; }

 private:
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  alignas(64) std::array<T, Capacity> slots_{};
};

}  // namespace cncd::motion
