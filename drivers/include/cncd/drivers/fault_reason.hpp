// A human-readable fault reason that a driver's I/O thread publishes and any thread (the servo
// thread included) may read without locks.
#pragma once

#include <array>
#include <cstddef>
#include <cstring>

#include "cncd/drivers/rt.hpp"
#include "cncd/drivers/seqlock.hpp"

namespace cncd::drivers {

inline constexpr std::size_t kFaultReasonSize = 160;

// Copies `text` into `out` of `size` bytes, cut to fit and NUL-terminated. RT-safe: the servo
// thread copies words and formats none.
CNCD_RT inline void copy_text(char* out, std::size_t size, const char* text) noexcept {
  if (size == 0) return;
  const std::size_t n = strnlen(text, size - 1);
  std::memcpy(out, text, n);
  out[n] = '\0';
}

struct FaultText {
  std::array<char, kFaultReasonSize> text{};
};

class FaultReason {
 public:
  // One writer thread. An empty text clears the reason.
  void set(const char* text) noexcept {
    FaultText value;
    copy_text(value.text.data(), value.text.size(), text);
    text_.store(value);
  }
  void clear() noexcept { text_.store(FaultText{}); }
  // RT-safe, any thread: copies the reason (NUL-terminated, possibly empty) into `out`.
  CNCD_RT void copy(char* out, std::size_t size) const noexcept {
    FaultText value = text_.load();
    value.text.back() = '\0';
    copy_text(out, size, value.text.data());
  }

 private:
  Seqlock<FaultText> text_;
};

}  // namespace cncd::drivers
