#include "jog_heartbeat.hpp"

#include <fmt/format.h>

namespace cncd::daemon {

std::string jog_target_name(int target) {
  if (target >= motion::kJointJogBase)
    return fmt::format("joint {}", target - motion::kJointJogBase);
  if (target >= 0 && target < config::kMaxAxes)
    return std::string(1, config::kAxisLetters[static_cast<std::size_t>(target)]);
  return "?";
}

void JogHeartbeats::started(int axis, std::uint64_t connection, double heartbeat_s, std::string who,
                            Clock::time_point now) {
  Watch& watch = watches_.at(static_cast<std::size_t>(axis));
  if (heartbeat_s <= 0) {
    watch = Watch{};
    return;
  }
  watch.active = true;
  watch.connection = connection;
  watch.period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(heartbeat_s));
  watch.due = now + watch.period;
  watch.who = std::move(who);
}

void JogHeartbeats::forget(int axis) {
  watches_.at(static_cast<std::size_t>(axis)) = Watch{};
}

std::vector<int> JogHeartbeats::beat(std::uint64_t connection, int axis, Clock::time_point now) {
  std::vector<int> kept;
  for (std::size_t i = 0; i < watches_.size(); ++i) {
    Watch& watch = watches_[i];
    if (!watch.active || watch.connection != connection) continue;
    if (axis >= 0 && static_cast<std::size_t>(axis) != i) continue;
    watch.due = now + watch.period;
    kept.push_back(static_cast<int>(i));
  }
  return kept;
}

void JogHeartbeats::closed(std::uint64_t connection) {
  for (std::size_t i = 0; i < watches_.size(); ++i) {
    if (watches_[i].active && watches_[i].connection == connection)
      stop(static_cast<int>(i), "the connection that started it closed");
  }
}

void JogHeartbeats::expire(Clock::time_point now) {
  for (std::size_t i = 0; i < watches_.size(); ++i) {
    const Watch& watch = watches_[i];
    if (!watch.active || now < watch.due) continue;
    stop(static_cast<int>(i), fmt::format("no jog.heartbeat came for {:g} s",
                                          std::chrono::duration<double>(watch.period).count()));
  }
}

int JogHeartbeats::ms_until_due(Clock::time_point now) const {
  int wait_ms = -1;
  for (const auto& watch : watches_) {
    if (!watch.active) continue;
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(watch.due - now).count();
    const int ms = left < 0 ? 0 : static_cast<int>(left);
    wait_ms = wait_ms < 0 ? ms : std::min(wait_ms, ms);
  }
  return wait_ms;
}

void JogHeartbeats::stop(int axis, const std::string& why) {
  Watch& watch = watches_.at(static_cast<std::size_t>(axis));
  // Harmless when the jog has ended otherwise (estop, the soft limit): jog.stop of an axis at
  // rest does nothing, and then there is nothing to tell.
  const bool jogging = task_.status().motion == motion::MotionState::jogging;
  task_.jog_stop(axis);
  if (jogging)
    events_.add("warning", "jog",
                fmt::format("{} jog of {} stopped: {}", jog_target_name(axis), watch.who, why));
  watch = Watch{};
}

}  // namespace cncd::daemon
