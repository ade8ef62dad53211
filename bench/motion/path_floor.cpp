#include "path_floor.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "cncd/pipeline/plan_geometry.hpp"

namespace cncd::bench {
namespace {

using motion::kAxes;
using motion::Segment;
constexpr double kStep = 0.005;  // integration step along the path (units)

bool is_line(const Segment& move) {
  return move.kind == Segment::Kind::line && move.length > 0;
}

int direction(const Segment& move, int axis) {
  const double d = move.end[axis] - move.start[axis];
  if (std::abs(d) <= 1e-9 * move.length) return 0;
  return d > 0 ? 1 : -1;
}

// Where each axis last rested (or will next rest): positions, or NaN where unknown (then the
// axis sets no cap there).
using Rests = std::array<double, kAxes>;

// Rest points of the moves, looking back (`forward`) or ahead. `reversals`: every junction
// where an axis changes direction (starts, stops or reverses) is one; otherwise only the
// path's end, and only up to the axis's first change of direction from there.
std::vector<Rests> rests(const std::vector<Segment>& moves, bool forward, bool reversals) {
  const std::size_t n = moves.size();
  std::vector<Rests> out(n);
  Rests current{};
  const Segment& edge = forward ? moves.front() : moves.back();
  for (int k = 0; k < kAxes; ++k)
    current[k] = forward ? edge.start[k] : edge.end[k];
  for (std::size_t step = 0; step < n; ++step) {
    const std::size_t i = forward ? step : n - 1 - step;
    if (step > 0) {
      const Segment& here = moves[i];
      const Segment& before = moves[forward ? i - 1 : i + 1];
      for (int k = 0; k < kAxes; ++k) {
        if (!is_line(here) || !is_line(before)) {
          current[k] = NAN;  // an arc or a dwell in between: no claim across it
        } else if (direction(here, k) != direction(before, k)) {
          current[k] = reversals ? (forward ? here.start[k] : here.end[k]) : NAN;
        }
      }
    }
    out[i] = current;
  }
  return out;
}

double floor_s(const config::MachineConfig& machine, const std::vector<Segment>& moves,
               bool reversals) {
  const auto back = rests(moves, true, reversals);
  const auto ahead = rests(moves, false, reversals);
  double total = 0;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const Segment& move = moves[i];
    if (move.kind == Segment::Kind::dwell) {
      total += move.dwell_s;
      continue;
    }
    const double velocity = pipeline::move_limits(machine, move).velocity;
    if (!is_line(move)) {
      if (velocity < 1e300) total += move.length / velocity;
      continue;
    }
    const int steps = std::max(1, static_cast<int>(std::ceil(move.length / kStep)));
    const double ds = move.length / steps;
    for (int j = 0; j < steps; ++j) {
      double t = velocity < 1e300 ? ds / velocity : 0;
      for (int k = 0; k < kAxes; ++k) {
        const auto& axis = machine.axes[static_cast<std::size_t>(k)];
        const double d = move.end[k] - move.start[k];
        if (!axis.present || direction(move, k) == 0) continue;
        const double x0 = move.start[k] + d * j / steps;
        const double x1 = move.start[k] + d * (j + 1) / steps;
        // Axis k at rest at `rest`: within distance r of it its speed is at most
        // sqrt(2 A r); over this step that takes at least sqrt(2/A) (sqrt(r1) - sqrt(r0)).
        const double scale = std::sqrt(2.0 / axis.max_acceleration);
        if (!std::isnan(back[i][k]))
          t = std::max(t, scale * (std::sqrt(std::abs(x1 - back[i][k])) -
                                   std::sqrt(std::abs(x0 - back[i][k]))));
        if (!std::isnan(ahead[i][k]))
          t = std::max(t, scale * (std::sqrt(std::abs(ahead[i][k] - x0)) -
                                   std::sqrt(std::abs(ahead[i][k] - x1))));
      }
      total += t;
    }
  }
  return total;
}

}  // namespace

PathFloors path_floors(const config::MachineConfig& machine,
                       const std::vector<motion::Segment>& moves) {
  PathFloors floors;
  if (moves.empty()) return floors;
  for (const Segment& move : moves) {
    floors.length += move.length;
    if (move.kind == Segment::Kind::dwell) {
      floors.bound_s += move.dwell_s;
      continue;
    }
    const double velocity = pipeline::move_limits(machine, move).velocity;
    if (move.length > 0 && velocity < 1e300) floors.bound_s += move.length / velocity;
  }
  floors.start_stop_s = floor_s(machine, moves, false);
  floors.exact_path_s = floor_s(machine, moves, true);
  return floors;
}

}  // namespace cncd::bench
