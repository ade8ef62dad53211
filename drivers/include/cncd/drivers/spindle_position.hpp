// A spindle position read from a register now and then (a Modbus servo spindle or a VFD that
// reports its shaft position), made into a position at any moment:
// - the register counts modulo 2^width, so each reading is unwrapped to the whole count nearest
//   to where the spindle was predicted to be;
// - the readings feed a tracking filter of position, speed and acceleration (an alpha-beta-gamma
//   filter, critically damped), which predicts the position between readings, so that a reading
//   one bus period old is not taken for the spindle's position now (at 600 rpm a reading 10 ms
//   old is a tenth of a revolution behind), and which smooths the jitter of when each reading
//   was taken;
// - what a new reading corrects is spread over the time to the next one, so the position the
//   servo thread sees moves smoothly and never jumps.
#pragma once

#include <cstdint>

#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

// The spindle's motion as of one reading.
struct SpindlePositionFit {
  bool valid = false;       // at least one reading
  double revolutions = 0;   // at time_ns, signed (forward counts up)
  double rps = 0;           // revolutions per second at time_ns
  double acceleration = 0;  // revolutions per second squared
  std::int64_t time_ns = 0;
  // What the previous estimate said at time_ns less `revolutions`: faded out over blend_ns.
  double correction = 0;
  std::int64_t blend_ns = 0;
  // RT: the position predicted at `now_ns`, never more than `horizon_ns` past the reading
  // (beyond that the reading is stale and the prediction stops there).
  CNCD_RT double at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept;
  // RT: the filter's speed at `now_ns` (without the fading correction).
  CNCD_RT double rps_at(std::int64_t now_ns, std::int64_t horizon_ns) const noexcept;
};

class SpindlePositionTracker {
 public:
  // Non-RT. `width`: 16 or 32 bits. `counts_per_rev`: nonzero, negative for a register that
  // counts down while the spindle turns forward. `max_acceleration` (rev/s^2, 0 = unknown):
  // the filter's acceleration is held within twice it. Readings more than `gap_ns` apart (a bus
  // that was down) start the filter afresh at the mean speed across the gap.
  void configure(int width, double counts_per_rev, double max_acceleration,
                 std::int64_t gap_ns) noexcept;
  // The register as read at `time_ns` (CLOCK_MONOTONIC). Returns the new fit.
  CNCD_RT const SpindlePositionFit& add(std::uint32_t raw, std::int64_t time_ns) noexcept {
    return add(raw, time_ns, time_ns);
  }
  // The register as read somewhen from `earliest_ns` to `latest_ns` (the request reached the
  // drive, its answer set off). The reading is placed in the middle of the drive's usual answer
  // time. An answer much slower than usual (a request or answer that waited somewhere) leaves
  // the moment of the reading unknown: it is unwrapped, but the filter keeps to the others,
  // unless the drive has answered that slowly several times in a row.
  CNCD_RT const SpindlePositionFit& add(std::uint32_t raw, std::int64_t earliest_ns,
                                        std::int64_t latest_ns) noexcept;
  CNCD_RT const SpindlePositionFit& fit() const noexcept { return fit_; }
  // The unwrapped count of the latest reading.
  CNCD_RT std::int64_t counts() const noexcept { return count_; }

 private:
  int width_ = 32;
  double counts_per_rev_ = 1;
  double max_acceleration_ = 0;
  std::int64_t gap_ns_ = 0;
  std::int64_t count_ = 0;
  int readings_ = 0;                     // since the filter started, counted up to 3
  std::int64_t typical_window_ns_ = -1;  // the drive's usual answer time, -1: none yet
  int doubtful_ = 0;                     // slow answers in a row
  SpindlePositionFit fit_{};
};

}  // namespace cncd::drivers
