// Logging set-up for cncd and its tools. Under systemd (JOURNAL_STREAM set and pointing at our
// stderr) each line carries a "<N>" syslog priority prefix that journald turns into the
// entry's priority; on a terminal lines carry a time stamp and a level name.
#pragma once

#include <optional>
#include <string>

#include <spdlog/common.h>

namespace cncd::daemon {

// Parses "trace|debug|info|warn|warning|error|critical|off"; nullopt when unknown.
std::optional<spdlog::level::level_enum> parse_log_level(const std::string& name);

// Installs the default logger writing to stderr. Call once, before other threads start.
void init_logging(spdlog::level::level_enum level);

}  // namespace cncd::daemon
