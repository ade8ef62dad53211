#include "cncd/motion/command_history.hpp"

#include <algorithm>

namespace cncd::motion {

CommandHistory::CommandHistory(int joints, std::size_t depth)
    : joints_(std::max(joints, 0)),
      depth_(std::max<std::size_t>(depth, 1)),
      entries_(depth_ * static_cast<std::size_t>(joints_)) {}

std::size_t CommandHistory::depth_for(std::int64_t deadline_ns, std::int64_t period_ns) noexcept {
  std::size_t needed = kMinDepth;
  if (deadline_ns > 0 && period_ns > 0) {
    // Two more: the cycle being checked and the one whose command is being written.
    const std::int64_t periods = deadline_ns / period_ns + 2;
    needed = periods >= static_cast<std::int64_t>(kMaxDepth)
                 ? kMaxDepth
                 : std::max(needed, static_cast<std::size_t>(periods));
  }
  std::size_t depth = kMinDepth;
  while (depth < needed)
    depth *= 2;
  return depth;
}

void CommandHistory::record(std::uint64_t cycle, const drivers::JointCommand* commands) noexcept {
  if (cycle == 0 || (latest_ != 0 && cycle <= latest_)) return;
  // A gap (cycles not recorded) starts the history afresh: older slots would be misread.
  if (first_ == 0 || cycle != latest_ + 1) first_ = cycle;
  latest_ = cycle;
  std::copy_n(commands, joints_,
              entries_.begin() + static_cast<std::ptrdiff_t>((cycle % depth_) *
                                                             static_cast<std::size_t>(joints_)));
}

std::uint64_t CommandHistory::oldest() const noexcept {
  if (latest_ == 0) return 0;
  return latest_ - first_ + 1 > depth_ ? latest_ - depth_ + 1 : first_;
}

const drivers::JointCommand* CommandHistory::find(int joint, std::uint64_t cycle) const noexcept {
  if (latest_ == 0 || joint < 0 || joint >= joints_) return nullptr;
  std::uint64_t at = cycle;
  if (at == 0 || at > latest_) at = latest_;
  at = std::max(at, oldest());
  return &entries_[(at % depth_) * static_cast<std::size_t>(joints_) +
                   static_cast<std::size_t>(joint)];
}

}  // namespace cncd::motion
