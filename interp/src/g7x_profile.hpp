// The geometry of the lathe roughing and finishing cycles (G70, G71, G72): a profile of lines
// and arcs in the cycle's own frame (u, v), where roughing passes run at constant u toward -v
// and step down in u from the start point, its offset by the stock to leave, and where a pass
// line meets it.
#pragma once

#include <optional>
#include <vector>

namespace cncd::interp::g7x {

struct Pt {
  double u = 0;
  double v = 0;
};

struct Seg {
  Pt a;  // start
  Pt b;  // end
  bool arc = false;
  Pt c;              // arc center
  bool ccw = false;  // arc turns from +u toward +v
  double round = 0;  // the radius that rounds the corner at its end, 0 = sharp
};

using Path = std::vector<Seg>;

inline Seg line(Pt a, Pt b) {
  Seg seg;
  seg.a = a;
  seg.b = b;
  return seg;
}

inline constexpr double kEps = 1e-9;

// The corners between lines that ask for it rounded by an arc of that radius.
Path round_corners(const Path& path);

// The profile moved `d` to the left of its direction of travel (the side of the stock): each
// piece moved, the gap at an outside corner closed by an arc of radius `d` around it, the
// overlap at an inside corner cut where the two pieces meet.
Path offset_path(const Path& path, double d);

// The v of every point where the line u = `level` meets `seg`.
void level_hits(const Seg& seg, double level, std::vector<double>& out);

// The highest v below `below` where the line u = `level` meets `path`; `fallback` if none.
double next_hit(const Path& path, double level, double below, double fallback);

// The point of `seg` at u = `level` (for an arc, the first from its start, or the `last`).
Pt point_at(const Seg& seg, double level, bool last = false);

// `seg` from its start to `p` and from `p` to its end.
Seg head(const Seg& seg, Pt p);
Seg tail(const Seg& seg, Pt p);

// Whether v never rises along `seg` (the roughing cycles' profiles run one way).
bool v_never_rises(const Seg& seg);

// Whether u falls along the whole of `seg` (its end lower than its start).
bool descends(const Seg& seg);

// The point of highest u on the arc `seg`, when its sweep reaches it.
std::optional<Pt> arc_peak(const Seg& seg);

// The point of lowest u on the arc `seg`, when its sweep reaches it.
std::optional<Pt> arc_valley(const Seg& seg);

// The lowest u on `path`.
double lowest_u(const Path& path);

// One move of a cycle, in its frame.
struct Move {
  enum class Kind { traverse, feed, arc } kind = Kind::feed;
  Seg seg;  // from the previous move's end to seg.b
};
using Moves = std::vector<Move>;

// The roughing passes at u = start.u, start.u - step, ... above the lowest point of `path`,
// each from the line between `entry` and the path's start to where it meets the path, backing
// off by `retract` on the way back.
void rough(const Path& path, Pt entry, double step, double retract, Moves& out);

// Along `path`: lines fed, arcs cut. With `pockets`, every stretch where u falls is cut as it
// is met, in passes at grid, grid - step, ... (with a NaN grid: from the stretch's top); with
// `monotonic`, such stretches are left out instead, and each line is fed from its start.
enum class Follow { plain, pockets, monotonic };
void follow(const Path& path, Follow how, double step, double retract, double grid, Moves& out);

}  // namespace cncd::interp::g7x
