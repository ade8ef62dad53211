// Cutter radius compensation's state (G40, G41, G42, G41.1, G42.1) and its plane geometry.
// The compensated path is worked out in the plane's own two coordinates, "a" and "b" (XY: X Y,
// XZ: Z X, as ARC_FEED names them), with "c" on the plane's normal.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

enum class CompSide : std::uint8_t { off, left, right };

struct PlanePoint {
  double a = 0;
  double b = 0;
};

// One canonical command held back until the next move fixes where the tool may go: a move
// (its plane end point may still change), or a command that has to stay behind the moves.
// LinuxCNC works its angles out against a long double pi; the same rounding keeps the last
// digit (and the sign of a zero) its canon prints.
inline constexpr long double kPiL = 3.141592653589793238462643383279502884L;
inline constexpr long double kHalfPiL = kPiL / 2.0L;

inline PlanePoint along(PlanePoint from, double length, double angle) {
  return {from.a + length * std::cos(angle), from.b + length * std::sin(angle)};
}
inline double direction(PlanePoint from, PlanePoint to) {
  return std::atan2(to.b - from.b, to.a - from.a);
}
inline double distance(PlanePoint p, PlanePoint q) {
  return std::hypot(p.a - q.a, p.b - q.b);
}

struct QueuedCanon {
  CanonCommand command;
  // Straight moves: their programmed direction in the plane, to tell a move the corner
  // shortens from one it would reverse (a gouge).
  PlanePoint direction;
  double original_turn = 0;  // arcs: the programmed sweep, radians counterclockwise
};

struct CompState {
  CompSide side = CompSide::off;
  double radius = 0;  // program units, never negative
  int orientation = 0;
  bool first_move = true;        // the next move in the plane is the entry move
  bool arc_not_allowed = false;  // the move after G40 must be straight
  Pose program{};                // the programmed (uncompensated) end of the last move
  std::vector<QueuedCanon> queue;
  PlanePoint start;  // where the first queued move starts, when start_valid
  bool start_valid = false;

  bool on() const { return side != CompSide::off; }
  bool active() const { return on() && radius > 0.0; }
};

// The plane's axes as cutter compensation names them: XY (X, Y, Z) or XZ (Z, X, Y).
struct CompAxes {
  std::size_t a;
  std::size_t b;
  std::size_t c;
};
CompAxes comp_axes(Plane plane);

// The angle an arc sweeps from (x1, y1) to (x2, y2) around the center, counterclockwise
// positive; `turn` counts the turns and gives the direction (LinuxCNC's sweep, whole extra
// turns included, 0 when turn is 0).
double arc_sweep(PlanePoint start, PlanePoint center, int turn, PlanePoint end);

// The tool is inside an arc when it keeps left of a counterclockwise one or right of a
// clockwise one.
inline bool tool_inside_arc(CompSide side, int turn) {
  return (side == CompSide::left && turn > 0) || (side == CompSide::right && turn < 0);
}

}  // namespace cncd::interp
