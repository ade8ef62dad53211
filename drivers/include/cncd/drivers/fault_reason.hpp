// A human-readable fault reason that a driver's I/O thread publishes and any thread (the servo
// thread included) may read without locks.
#pragma once

#include <array>
#include <cstddef>
#include <cstdio>

#include "cncd/drivers/seqlock.hpp"

namespace cncd::drivers {

inline constexpr std::size_t kFaultReasonSize = 160;

struct FaultText {
  std::array<char, kFaultReasonSize> text{};
};

class FaultReason {
 public:
  // One writer thread. An empty text clears the reason.
  void set(const char* text) noexcept {
    FaultText value;
    std::snprintf(value.text.data(), value.text.size(), "%s", text);
    text_.store(value);
  }
  void clear() noexcept { text_.store(FaultText{}); }
  // RT-safe, any thread: copies the reason (NUL-terminated, possibly empty) into `out`.
  void copy(char* out, std::size_t size) const noexcept {
    if (size == 0) return;
    const FaultText value = text_.load();
    std::snprintf(out, size, "%s", value.text.data());
  }

 private:
  Seqlock<FaultText> text_;
};

}  // namespace cncd::drivers
