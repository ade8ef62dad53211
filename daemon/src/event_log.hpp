// Recent errors and events, each with a sequence number. Every client sees every entry: they
// are broadcast and kept for errors.list, never consumed by whoever reads first.
// Used on the daemon's main loop thread only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace cncd::daemon {

struct Event {
  std::uint64_t seq = 0;
  double time = 0;    // seconds since the Unix epoch
  std::string level;  // "error" | "warning" | "info"
  std::string kind;   // "program" | "fault" | "machine" | "message" ...
  std::string message;
  std::string by;    // who caused it: the peer, or a person through it; empty when no request did
  std::string code;  // the servo thread's event code ("following_error"), empty for others
};

class EventLog {
 public:
  static constexpr std::size_t kCapacity = 1000;

  // Records an event (and logs it through spdlog at the matching level).
  void add(std::string level, std::string kind, std::string message);
  // The same, with the servo thread's code for the event.
  void add(std::string level, std::string kind, std::string message, std::string code);
  // Who the entries added from now on are caused by ("" when by no request).
  void set_actor(std::string by) { actor_ = std::move(by); }
  const std::string& actor() const { return actor_; }
  // Events with seq > since, oldest first.
  std::vector<Event> since(std::uint64_t since) const;
  std::uint64_t last_seq() const { return next_seq_ - 1; }

 private:
  std::deque<Event> events_;
  std::uint64_t next_seq_ = 1;
  std::string actor_;
};

}  // namespace cncd::daemon
