// Continuous jogs kept alive by their client: a jog.start with "heartbeat_s" runs only while
// jog.heartbeat keeps coming from the connection that started it, and stops (as jog.stop does,
// under control) when it stops coming or that connection closes. A front end whose page or
// network dies mid-jog thus cannot leave an axis running. Loop thread only. Jogs are counted
// by target: an axis index, or motion::kJointJogBase + a joint's number (joint mode).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/jog.hpp"
#include "event_log.hpp"
#include "task.hpp"

namespace cncd::daemon {

// A jog target as the operator reads it: "X", "joint 2".
std::string jog_target_name(int target);

class JogHeartbeats {
 public:
  using Clock = std::chrono::steady_clock;

  JogHeartbeats(Task& task, EventLog& events) : task_(task), events_(events) {}

  // A jog.start on `axis` from `connection` has been accepted: watched from now on when
  // `heartbeat_s` > 0, else (a jog without heartbeat has taken the axis over) no longer.
  // `who` names the sender in the event of a stop.
  void started(int axis, std::uint64_t connection, double heartbeat_s, std::string who,
               Clock::time_point now);
  // The axis's jog was stopped or replaced by an increment: nothing to watch.
  void forget(int axis);
  // jog.heartbeat from `connection` for `axis` (-1: all its jogs). Returns the axes it keeps.
  std::vector<int> beat(std::uint64_t connection, int axis, Clock::time_point now);
  // The connection is closing: its watched jogs stop.
  void closed(std::uint64_t connection);
  // Stops the watched jogs whose heartbeat is overdue.
  void expire(Clock::time_point now);
  // Milliseconds (rounded up) until the next heartbeat is due, 0 when one is overdue, -1 when
  // no jog is watched: the loop waits no longer than that.
  int ms_until_due(Clock::time_point now) const;

 private:
  struct Watch {
    bool active = false;
    std::uint64_t connection = 0;
    Clock::duration period{};
    Clock::time_point due;
    std::string who;
  };
  void stop(int axis, const std::string& why);

  Task& task_;
  EventLog& events_;
  std::array<Watch, motion::kJogTargets> watches_{};
};

}  // namespace cncd::daemon
