// Where a program's moves go: the motion controller's queue in the daemon, a planner of its own
// in the plan simulation, the reach and extent check in cncd-check. pipeline::ProgramRunner
// hands every move of a program to one. One thread at a time.
#pragma once

#include <string>

#include "cncd/motion/types.hpp"

namespace cncd::motion {

class MoveQueue {
 public:
  enum class Push { accepted, full, refused };
  virtual ~MoveQueue() = default;
  // Whether the next move may be handed on now (a stop point included); false also stops the
  // program being read ahead of what the queue can take.
  virtual bool ready() { return true; }
  // Queues one move. `full`: no room now, the same move is offered again later. `refused`: it
  // cannot be made, refusal() says why.
  virtual Push push_move(const Move& move) = 0;
  // A stop point: the move held back for look-ahead goes out, the path comes to rest there.
  virtual void end_path() = 0;
  // Why the last move refused was refused.
  virtual std::string refusal() const = 0;
};

}  // namespace cncd::motion
