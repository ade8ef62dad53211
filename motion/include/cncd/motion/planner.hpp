// Turns programmed moves into segments whose every axis stays within its MAX_VELOCITY and
// MAX_ACCELERATION: the path limits are the tightest the axes allow along the move's direction
// (and, on arcs, with the centripetal acceleration included). Each segment carries its end
// tangents: under G61/G64 the servo loop crosses a tangent junction at speed, any other
// junction at rest. Non-RT: called on the task thread.
#pragma once

#include <optional>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class Planner {
 public:
  explicit Planner(const config::MachineConfig& config);

  // Plans `move` starting at `start`. Returns nullopt and sets `error` when the move cannot be
  // made (a zero feed, an arc whose ends are not on one circle, an end outside the soft limits
  // of an axis in `check_limits`).
  std::optional<Segment> plan(const Move& move, const AxisPose& start, bool check_limits,
                              std::string& error) const;

 private:
  bool within_limits(const Segment& segment, std::string& error) const;
  const config::MachineConfig& config_;
};

}  // namespace cncd::motion
