// The control lease: "one hand on the machine". Motion methods (roles.hpp, needs_lease) are
// forwarded only for the web session that holds it; everyone sees who does. Thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "cncd/web/sessions.hpp"

namespace cncd::web {

struct LeaseHolder {
  std::string session;  // Session::id
  std::string user;
  std::string address;
  TimePoint since;
};

class ControlLease {
 public:
  // Called after every change with the new holder (nullopt: free) and the new version,
  // outside the lease's lock (it may call back into the lease).
  using Observer = std::function<void(const std::optional<LeaseHolder>&, std::uint64_t)>;

  explicit ControlLease(Clock clock = system_clock());

  struct TakeResult {
    bool ok = false;
    // ok: the holder now (this session). Refused: the session that holds it.
    std::optional<LeaseHolder> holder;
  };
  // Takes the lease for `session` when free or already its own (then unchanged: no
  // notification); from another session only with `force`.
  TakeResult take(const Session& session, bool force);
  // Releases it when `session_id` holds it; true when it did.
  bool release(std::string_view session_id);
  // The session's last WebSocket closed, it logged out or expired: same as release.
  void session_closed(std::string_view session_id) { release(session_id); }

  std::optional<LeaseHolder> holder() const;
  bool held_by(std::string_view session_id) const;
  // Counts changes, starting at 0.
  std::uint64_t version() const;
  void set_observer(Observer observer);

 private:
  void notify(const std::optional<LeaseHolder>& holder, std::uint64_t version);

  Clock clock_;
  mutable std::mutex mutex_;
  std::optional<LeaseHolder> holder_;
  std::uint64_t version_ = 0;
  Observer observer_;
};

}  // namespace cncd::web
