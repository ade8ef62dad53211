#include "cncd/web/sessions.hpp"

#include <algorithm>
#include <utility>

#include "crypto.hpp"

namespace cncd::web {

Clock system_clock() {
  return [] { return std::chrono::system_clock::now(); };
}

SessionStore::SessionStore(std::chrono::seconds lifetime, Clock clock)
    : lifetime_(lifetime), clock_(std::move(clock)) {}

Session SessionStore::create(std::string user, Role role, std::string address) {
  Session s;
  s.token = crypto::hex(crypto::random_bytes(32));
  s.id = crypto::hex(crypto::random_bytes(8));
  s.user = std::move(user);
  s.role = role;
  s.address = std::move(address);
  s.created = clock_();
  s.expires = s.created + lifetime_;
  const std::string key = crypto::sha256_hex(s.token);
  std::lock_guard lock(mutex_);
  by_hash_[key] = s;
  return s;
}

std::optional<Session> SessionStore::find(std::string_view token) {
  const std::string key = crypto::sha256_hex(token);
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  const auto it = by_hash_.find(key);
  if (it == by_hash_.end()) return std::nullopt;
  if (now >= it->second.expires) {
    by_hash_.erase(it);
    return std::nullopt;
  }
  return it->second;
}

std::optional<Session> SessionStore::find_id(std::string_view id) {
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  for (const auto& [key, s] : by_hash_) {
    if (s.id == id && now < s.expires) return s;
  }
  return std::nullopt;
}

bool SessionStore::drop(std::string_view token) {
  const std::string key = crypto::sha256_hex(token);
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  const auto it = by_hash_.find(key);
  if (it == by_hash_.end()) return false;
  const bool live = now < it->second.expires;
  by_hash_.erase(it);
  return live;
}

std::vector<std::string> SessionStore::drop_user(std::string_view user) {
  std::vector<std::string> ids;
  std::lock_guard lock(mutex_);
  for (auto it = by_hash_.begin(); it != by_hash_.end();) {
    if (it->second.user == user) {
      ids.push_back(it->second.id);
      it = by_hash_.erase(it);
    } else {
      ++it;
    }
  }
  return ids;
}

std::vector<std::string> SessionStore::expire() {
  std::vector<std::string> ids;
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  for (auto it = by_hash_.begin(); it != by_hash_.end();) {
    if (now >= it->second.expires) {
      ids.push_back(it->second.id);
      it = by_hash_.erase(it);
    } else {
      ++it;
    }
  }
  return ids;
}

std::size_t SessionStore::size() const {
  std::lock_guard lock(mutex_);
  return by_hash_.size();
}

LoginLimiter::LoginLimiter(Clock clock, int max_failures, std::chrono::seconds window,
                           std::size_t max_tracked)
    : clock_(std::move(clock)),
      max_failures_(max_failures),
      window_(window),
      max_tracked_(max_tracked) {}

void LoginLimiter::prune(std::map<std::string, Failures, std::less<>>& map, TimePoint now) {
  for (auto it = map.begin(); it != map.end();) {
    auto& times = it->second;
    times.erase(
        std::remove_if(times.begin(), times.end(), [&](TimePoint t) { return t + window_ <= now; }),
        times.end());
    it = times.empty() ? map.erase(it) : std::next(it);
  }
}

std::chrono::seconds LoginLimiter::wait(const std::map<std::string, Failures, std::less<>>& map,
                                        std::string_view key, TimePoint now) const {
  const auto it = map.find(key);
  if (it == map.end() || static_cast<int>(it->second.size()) < max_failures_) {
    return std::chrono::seconds(0);
  }
  // The failures are in time order: the wait ends when enough of them have left the window.
  const auto& times = it->second;
  const TimePoint free_at = times[times.size() - static_cast<std::size_t>(max_failures_)] + window_;
  const auto left = std::chrono::ceil<std::chrono::seconds>(free_at - now);
  return std::max(left, std::chrono::seconds(1));
}

void LoginLimiter::record(std::map<std::string, Failures, std::less<>>& map, std::string_view key,
                          TimePoint now) {
  auto it = map.find(key);
  if (it == map.end()) {
    if (map.size() >= max_tracked_) {
      // Forget the one whose last failure is oldest.
      const auto oldest = std::min_element(
          map.begin(), map.end(),
          [](const auto& a, const auto& b) { return a.second.back() < b.second.back(); });
      map.erase(oldest);
    }
    it = map.emplace(std::string(key), Failures{}).first;
  }
  it->second.push_back(now);
  // Only the last max_failures_ matter for the wait.
  if (it->second.size() > static_cast<std::size_t>(max_failures_)) {
    it->second.erase(it->second.begin());
  }
}

std::chrono::seconds LoginLimiter::retry_after(std::string_view address, std::string_view user) {
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  prune(by_address_, now);
  prune(by_user_, now);
  return std::max(wait(by_address_, address, now), wait(by_user_, user, now));
}

void LoginLimiter::failed(std::string_view address, std::string_view user) {
  const TimePoint now = clock_();
  std::lock_guard lock(mutex_);
  record(by_address_, address, now);
  record(by_user_, user, now);
}

void LoginLimiter::succeeded(std::string_view user) {
  std::lock_guard lock(mutex_);
  if (const auto it = by_user_.find(user); it != by_user_.end()) by_user_.erase(it);
}

}  // namespace cncd::web
