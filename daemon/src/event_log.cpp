#include "event_log.hpp"

#include <chrono>

#include <spdlog/spdlog.h>

namespace cncd::daemon {

void EventLog::add(std::string level, std::string kind, std::string message) {
  add(std::move(level), std::move(kind), std::move(message), "");
}

void EventLog::add(std::string level, std::string kind, std::string message, std::string code) {
  // The log line names who, unless the message does already.
  const std::string by =
      actor_.empty() || message.find(actor_) != std::string::npos ? "" : " (by " + actor_ + ")";
  if (level == "error") {
    spdlog::error("{}: {}{}", kind, message, by);
  } else if (level == "warning") {
    spdlog::warn("{}: {}{}", kind, message, by);
  } else {
    spdlog::info("{}: {}{}", kind, message, by);
  }
  const auto wall = std::chrono::system_clock::now().time_since_epoch();
  events_.push_back(Event{next_seq_++, std::chrono::duration<double>(wall).count(),
                          std::move(level), std::move(kind), std::move(message), actor_,
                          std::move(code)});
  if (events_.size() > kCapacity) events_.pop_front();
}

std::vector<Event> EventLog::since(std::uint64_t since) const {
  std::vector<Event> out;
  for (const auto& event : events_) {
    if (event.seq > since) out.push_back(event);
  }
  return out;
}

}  // namespace cncd::daemon
