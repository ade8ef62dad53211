// The motor commands of the last servo cycles, per joint, so that feedback measured in answer
// to an older command (drivers::JointFeedback::command_cycle) is compared with that command.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::motion {

class CommandHistory {
 public:
  // Non-RT: room for `joints` joints over at least `depth` cycles (allocated here, never later).
  CommandHistory(int joints, std::size_t depth);

  // Non-RT: the depth that keeps a deadline of `deadline_ns` in reach at `period_ns`: at least
  // kMinDepth cycles, a power of two, at most kMaxDepth.
  static std::size_t depth_for(std::int64_t deadline_ns, std::int64_t period_ns) noexcept;
  static constexpr std::size_t kMinDepth = 1024;
  static constexpr std::size_t kMaxDepth = std::size_t{1} << 20;

  // RT: the commands of servo cycle `cycle` (motor coordinates), one per joint, every cycle in
  // turn. An older cycle than the last is ignored; after a gap the history starts afresh.
  CNCD_RT void record(std::uint64_t cycle, const drivers::JointCommand* commands) noexcept;

  // RT: joint `joint`'s command of `cycle`. A cycle that fell out of the history gives the
  // oldest held; one not recorded yet (0 included) the latest. Nullptr while nothing is.
  CNCD_RT const drivers::JointCommand* find(int joint, std::uint64_t cycle) const noexcept;

  std::size_t depth() const noexcept { return depth_; }
  // The oldest and the latest cycle held (0 when none).
  CNCD_RT std::uint64_t oldest() const noexcept;
  std::uint64_t latest() const noexcept { return latest_; }

 private:
  int joints_;
  std::size_t depth_;
  std::vector<drivers::JointCommand> entries_;  // [cycle % depth_][joint]
  std::uint64_t first_ = 0;                     // the first cycle since the last gap
  std::uint64_t latest_ = 0;
};

}  // namespace cncd::motion
