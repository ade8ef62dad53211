// Lower bounds on the time to run a dense path from rest to rest, for the planner benchmark:
// how close to physics the planner gets, beyond the feed-limited bound (which lets every move
// start and end at full speed).
#pragma once

#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/segment.hpp"

namespace cncd::bench {

struct PathFloors {
  double length = 0;  // programmed path length (units)
  // Sum over the moves of length / the fastest speed the feed and the axes allow along them.
  double bound_s = 0;
  // The bound with the path starting and ending at rest: near its two ends every axis's speed
  // is capped by what it reaches from rest (or stops in) at its MAX_ACCELERATION over the
  // distance it has moved (or has left), so the ramps cost what the acceleration along the
  // path there allows.
  double start_stop_s = 0;
  // The same with every axis also at rest wherever it reverses, starts or stops along the path
  // (as it must where the programmed path is followed exactly: at a corner of a raster's row
  // end, X stops and Y starts). A blend within a tolerance P can do a little better at corners.
  double exact_path_s = 0;
};

// `moves`: the path's programmed moves in order (lines; other kinds count at their bound
// speed and break the chains of per-axis rest points around them).
PathFloors path_floors(const config::MachineConfig& machine,
                       const std::vector<motion::Segment>& moves);

}  // namespace cncd::bench
