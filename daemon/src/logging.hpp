// Logging set-up for cncd and its tools. Under systemd (JOURNAL_STREAM set and pointing at our
// stderr) each line carries a "<N>" syslog priority prefix that journald turns into the
// entry's priority; on a terminal lines carry a time stamp and a level name.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include <spdlog/common.h>

namespace cncd::daemon {

// Parses "trace|debug|info|warn|warning|error|critical|off"; nullopt when unknown.
std::optional<spdlog::level::level_enum> parse_log_level(const std::string& name);

// Installs the default logger writing to stderr. Call once, before other threads start.
void init_logging(spdlog::level::level_enum level);

// Lets at most `burst` messages of one kind through per `period` and counts the others; the
// next message let through says how many were left out. A failure that repeats every turn (no
// descriptors left, a client that reconnects in a loop) then cannot flood the log.
class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  LogLimiter(Clock::duration period, std::uint32_t burst) : period_(period), burst_(burst) {}
  // Logs `text` at `level` unless this kind's limit is reached; true when it did.
  bool log(spdlog::level::level_enum level, const std::string& text, Clock::time_point now);
  bool log(spdlog::level::level_enum level, const std::string& text) {
    return log(level, text, Clock::now());
  }
  // Messages left out since the last one let through.
  std::uint64_t left_out() const { return left_out_; }

 private:
  Clock::duration period_;
  std::uint32_t burst_;
  Clock::time_point window_start_{};
  std::uint32_t in_window_ = 0;
  std::uint64_t left_out_ = 0;
};

}  // namespace cncd::daemon
