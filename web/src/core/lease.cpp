#include "cncd/web/lease.hpp"

#include <utility>

namespace cncd::web {

ControlLease::ControlLease(Clock clock) : clock_(std::move(clock)) {}

ControlLease::TakeResult ControlLease::take(const Session& session, bool force) {
  std::optional<LeaseHolder> now;
  std::uint64_t version = 0;
  {
    std::lock_guard lock(mutex_);
    if (holder_ && holder_->session == session.id) return {true, holder_};
    if (holder_ && !force) return {false, holder_};
    holder_ = LeaseHolder{session.id, session.user, session.address, clock_()};
    now = holder_;
    version = ++version_;
  }
  notify(now, version);
  return {true, now};
}

bool ControlLease::release(std::string_view session_id) {
  std::uint64_t version = 0;
  {
    std::lock_guard lock(mutex_);
    if (!holder_ || holder_->session != session_id) return false;
    holder_.reset();
    version = ++version_;
  }
  notify(std::nullopt, version);
  return true;
}

std::optional<LeaseHolder> ControlLease::holder() const {
  std::lock_guard lock(mutex_);
  return holder_;
}

bool ControlLease::held_by(std::string_view session_id) const {
  std::lock_guard lock(mutex_);
  return holder_ && holder_->session == session_id;
}

std::uint64_t ControlLease::version() const {
  std::lock_guard lock(mutex_);
  return version_;
}

void ControlLease::set_observer(Observer observer) {
  std::lock_guard lock(mutex_);
  observer_ = std::move(observer);
}

void ControlLease::notify(const std::optional<LeaseHolder>& holder, std::uint64_t version) {
  Observer observer;
  {
    std::lock_guard lock(mutex_);
    observer = observer_;
  }
  if (observer) observer(holder, version);
}

}  // namespace cncd::web
