// A spindle position read from a register now and then (a Modbus servo spindle or a VFD that
// reports its shaft position), made into a position at any moment:
// - the register counts modulo 2^width, so each reading is unwrapped to the whole count nearest
//   to where the spindle was predicted to be;
// - between readings the position is predicted from the three latest ones (position, speed and
//   acceleration), so that a reading one bus period old is not taken for the spindle's position
//   now. At 600 rpm a reading 10 ms old is a tenth of a revolution behind.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

// The spindle's motion at one reading.
struct SpindlePositionFit {
  bool valid = false;       // at least one reading
  double revolutions = 0;   // at time_ns, signed (forward counts up)
  double rps = 0;           // revolutions per second at time_ns
  double acceleration = 0;  // revolutions per second squared
  std::int64_t time_ns = 0;
  // RT: the position predicted at `now_ns`, never more than `horizon_ns` past the reading
  // (beyond that the reading is stale and the prediction stops there).
  CNCD_RT double at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept;
  CNCD_RT double rps_at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept;
};

class SpindlePositionTracker {
 public:
  // Non-RT. `width`: 16 or 32 bits. `counts_per_rev`: nonzero, negative for a register that
  // counts down while the spindle turns forward. `max_acceleration` (rev/s^2, 0 = unknown):
  // the fit's acceleration is held within twice it. Readings more than `gap_ns` apart (a bus
  // that was down) start the fit afresh from the speed alone; the count carries on.
  void configure(int width, double counts_per_rev, double max_acceleration,
                 std::int64_t gap_ns) noexcept;
  // The register as read at `time_ns` (CLOCK_MONOTONIC). Returns the new fit.
  CNCD_RT const SpindlePositionFit& add(std::uint32_t raw, std::int64_t time_ns) noexcept;
  CNCD_RT const SpindlePositionFit& fit() const noexcept { return fit_; }
  // The unwrapped count of the latest reading.
  CNCD_RT std::int64_t counts() const noexcept { return count_; }

 private:
  struct Reading {
    std::int64_t counts = 0;
    std::int64_t time_ns = 0;
  };
  CNCD_RT void refit() noexcept;

  int width_ = 32;
  double counts_per_rev_ = 1;
  double max_acceleration_ = 0;
  std::int64_t gap_ns_ = 0;
  std::uint32_t last_raw_ = 0;
  std::int64_t count_ = 0;
  std::array<Reading, 3> history_{};  // newest first
  int readings_ = 0;                  // in history_, up to 3
  SpindlePositionFit fit_{};
};

}  // namespace cncd::drivers
