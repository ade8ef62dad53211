// When cncd feeds systemd's watchdog (WATCHDOG=1): only while the servo loop's heartbeat
// advances, so that systemd restarts a daemon whose servo thread has died or hangs even though
// its main loop still runs.
#pragma once

#include <chrono>
#include <cstdint>

namespace cncd::daemon {

class WatchdogGate {
 public:
  using Clock = std::chrono::steady_clock;

  // `interval`: how often the heartbeat is looked at (half of systemd's WATCHDOG_USEC);
  // `start`, `heartbeat`: the time and the servo heartbeat when the daemon became ready.
  WatchdogGate(std::chrono::microseconds interval, Clock::time_point start, std::uint64_t heartbeat)
      : interval_(interval), last_check_(start), last_heartbeat_(heartbeat) {}

  // Main thread, called as often as it likes: true when the watchdog is to be fed now, that is
  // once `interval` has passed since the last check and the heartbeat has moved since then.
  bool feed(Clock::time_point now, std::uint64_t heartbeat) {
    if (now - last_check_ < interval_) return false;
    const bool advanced = heartbeat != last_heartbeat_;
    last_heartbeat_ = heartbeat;
    last_check_ = now;
    return advanced;
  }

 private:
  std::chrono::microseconds interval_;
  Clock::time_point last_check_;
  std::uint64_t last_heartbeat_;
};

}  // namespace cncd::daemon
