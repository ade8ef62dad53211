// Logins: the sessions behind cookies, and the limiter that slows password guessing.
// Both are thread-safe (one mutex each) and take an injectable clock for tests.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "cncd/web/roles.hpp"

namespace cncd::web {

using TimePoint = std::chrono::system_clock::time_point;
using Clock = std::function<TimePoint()>;
// std::chrono::system_clock::now.
Clock system_clock();

struct Session {
  std::string token;  // the cookie's value: 64 hex digits from 32 random bytes (secret)
  std::string id;     // 16 hex digits, shown to others (lease holder, web.session)
  std::string user;
  Role role = Role::observer;
  std::string address;  // remote address at login
  TimePoint created;
  TimePoint expires;
};

class SessionStore {
 public:
  explicit SessionStore(std::chrono::seconds lifetime, Clock clock = system_clock());

  // A new session for a user who just logged in.
  Session create(std::string user, Role role, std::string address);
  // The live session of that token; nullopt when unknown or expired (an expired one is
  // dropped). Tokens are looked up by their SHA-256, so lookup time says nothing about them.
  std::optional<Session> find(std::string_view token);
  // The live session with that id (not the token).
  std::optional<Session> find_id(std::string_view id);
  // Logout. True when the token was live.
  bool drop(std::string_view token);
  // Every session of `user` (deleted, password changed); returns their ids, so that the
  // server can close their WebSockets and release their lease.
  std::vector<std::string> drop_user(std::string_view user);
  // Drops expired sessions; returns their ids.
  std::vector<std::string> expire();
  std::size_t size() const;

 private:
  std::chrono::seconds lifetime_;
  Clock clock_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Session> by_hash_;  // SHA-256 hex of the token -> session
};

// At most `max_failures` failed logins per remote address and per user name within `window`;
// past that, logins from that address or for that name are refused until the oldest failure
// leaves the window. Counts are kept for at most `max_tracked` addresses and names (the
// oldest forgotten first), so a flood of made-up names cannot exhaust memory.
class LoginLimiter {
 public:
  explicit LoginLimiter(Clock clock = system_clock(), int max_failures = 5,
                        std::chrono::seconds window = std::chrono::seconds(60),
                        std::size_t max_tracked = 10000);

  // Zero when a login from `address` for `user` may be tried now, else how long to wait
  // (whole seconds, at least 1: HTTP's Retry-After).
  std::chrono::seconds retry_after(std::string_view address, std::string_view user);
  void failed(std::string_view address, std::string_view user);
  // Forgets the user's failures (not the address's: one right password for one account must
  // not reopen guessing at the others).
  void succeeded(std::string_view user);

 private:
  using Failures = std::vector<TimePoint>;
  void prune(std::map<std::string, Failures, std::less<>>& map, TimePoint now);
  std::chrono::seconds wait(const std::map<std::string, Failures, std::less<>>& map,
                            std::string_view key, TimePoint now) const;
  void record(std::map<std::string, Failures, std::less<>>& map, std::string_view key,
              TimePoint now);

  Clock clock_;
  int max_failures_;
  std::chrono::seconds window_;
  std::size_t max_tracked_;
  std::mutex mutex_;
  std::map<std::string, Failures, std::less<>> by_address_;
  std::map<std::string, Failures, std::less<>> by_user_;
};

}  // namespace cncd::web
