// The passes of the G7x cycles, in the cycle's frame: roughing passes across the stock and the
// pass along the profile, with or without its pockets.
#include <cmath>
#include <optional>
#include <vector>

#include "g7x_profile.hpp"

namespace cncd::interp::g7x {
namespace {

void add(Moves& out, Move::Kind kind, Pt to) {
  Move move;
  move.kind = kind;
  move.seg.b = to;
  out.push_back(move);
}

bool is_point(const Seg& seg) {
  return std::fabs(seg.a.u - seg.b.u) < 1e-12 && std::fabs(seg.a.v - seg.b.v) < 1e-12;
}

// A piece of the profile: a line fed (even when it has no length), an arc cut unless it has no
// length (it would be a circle).
void add_piece(Moves& out, const Seg& piece) {
  if (!piece.arc) {
    add(out, Move::Kind::feed, piece.b);
  } else if (!is_point(piece)) {
    out.push_back(Move{Move::Kind::arc, piece});
  }
}

// One pass at u = level from v = from to where it meets the path; `back` is how the tool comes
// back to its start.
void pass(const Path& path, double level, double from, double retract, Move::Kind back,
          Moves& out) {
  const double end = next_hit(path, level, from, NAN);
  if (std::isnan(end)) return;
  // A short pass backs off by half its length at most, so that the way back does not cross it.
  retract = std::fmin(retract, (from - end) / 2);
  add(out, Move::Kind::feed, {level, end});
  add(out, Move::Kind::traverse, {level + retract, end + retract});
  add(out, Move::Kind::traverse, {level + retract, from - retract});
  add(out, back, {level, from});
}

// A piece of the path as the pockets see it; `joined` when it is the first part of an arc cut
// at its lowest point, which goes on in the next piece.
struct Piece {
  Seg seg;
  bool joined = false;
};

// The path with each arc that bulges above both its ends cut in two at its highest u, and each
// that dips below both at its lowest: u turns there.
std::vector<Piece> split_where_u_turns(const Path& path) {
  std::vector<Piece> out;
  for (const Seg& seg : path) {
    const double top = std::fmax(seg.a.u, seg.b.u), low = std::fmin(seg.a.u, seg.b.u);
    const std::optional<Pt> peak = seg.arc ? arc_peak(seg) : std::nullopt;
    const std::optional<Pt> valley = seg.arc ? arc_valley(seg) : std::nullopt;
    if (peak && peak->u > top + kEps) {
      out.push_back({head(seg, *peak)});
      out.push_back({tail(seg, *peak)});
    } else if (valley && valley->u < low - kEps) {
      out.push_back({head(seg, *valley), true});
      out.push_back({tail(seg, *valley)});
    } else {
      out.push_back({seg});
    }
  }
  return out;
}

// The pockets of a falling piece: passes at origin, origin - step, ... between its ends. Returns
// the rest of the piece, below the last pass. The lowest point of an arc (`valley`) that a pass
// level reaches is cut to, though the pass there has no length.
Seg pocket(const Path& path, const Seg& seg, bool valley, double origin, double step,
           double retract, Moves& out) {
  Seg rest = seg;
  for (int k = 0;; ++k) {
    const double level = origin - k * step;
    if (level <= seg.b.u + kEps) {
      if (valley && level > seg.b.u - 1e-6) {
        add_piece(out, rest);
        rest = tail(rest, rest.b);
      }
      break;
    }
    if (level > seg.a.u + kEps) continue;
    const Pt at = point_at(rest, level);
    add_piece(out, head(rest, at));
    rest = tail(rest, at);
    pass(path, level, at.v, retract, Move::Kind::feed, out);
  }
  return rest;
}

// Each piece at or above the highest u met so far, up to where u starts to fall: a line fed
// from its start, an arc that reaches that height entered by a feed to where it does, and cut
// when more than a point of it does.
void follow_monotonic(const Path& path, Moves& out) {
  double top = path.empty() ? 0.0 : path.front().a.u;
  for (const Seg& seg : path) {
    const bool start_in = seg.a.u >= top - kEps;
    const bool end_in = seg.b.u >= top - kEps;
    if (!start_in && !end_in) continue;
    Seg piece = seg;
    // An arc that dips below that height between its ends is taken up where it comes back.
    const std::optional<Pt> valley = seg.arc ? arc_valley(seg) : std::nullopt;
    if (!start_in || (end_in && valley && valley->u < top - kEps)) {
      piece = tail(seg, point_at(seg, top, true));
    } else if (!end_in) {
      piece = head(seg, point_at(seg, top));
    }
    // An arc that bulges past its end is cut at its highest point: u falls after it.
    const std::optional<Pt> peak = piece.arc && !is_point(piece) ? arc_peak(piece) : std::nullopt;
    if (peak && peak->u > piece.b.u + kEps) piece = head(piece, *peak);
    if (piece.arc || !is_point(piece)) {
      add(out, Move::Kind::feed, piece.a);
      add_piece(out, piece);
    }
    top = std::fmax(top, std::fmax(piece.a.u, piece.b.u));
  }
}

}  // namespace

void rough(const Path& path, Pt entry, double step, double retract, Moves& out) {
  if (path.empty()) return;
  const Pt start = path.front().a;
  const double low = lowest_u(path);
  for (double level = entry.u; level > low + kEps; level -= step) {
    double from = entry.v;
    if (std::fabs(entry.u - start.u) > kEps) {
      from = entry.v + (level - entry.u) / (start.u - entry.u) * (start.v - entry.v);
    }
    add(out, Move::Kind::traverse, {level, from});
    pass(path, level, from, retract, Move::Kind::traverse, out);
  }
}

void follow(const Path& path, Follow how, double step, double retract, double grid, Moves& out) {
  if (how == Follow::monotonic) {
    follow_monotonic(path, out);
    return;
  }
  if (how == Follow::plain) {
    for (const Seg& seg : path)
      add_piece(out, seg);
    return;
  }
  double peak = 0;
  bool falling = false;
  std::optional<Pt> carried;  // where the arc cut at its lowest point was left
  for (Piece piece : split_where_u_turns(path)) {
    Seg& seg = piece.seg;
    if (carried) seg.a = *carried;
    carried.reset();
    if (descends(seg)) {
      if (!falling) peak = seg.a.u;
      falling = true;
      seg = pocket(path, seg, piece.joined, std::isnan(grid) ? peak : grid, step, retract, out);
    } else {
      falling = false;
    }
    // Below the last pass, an arc cut at its lowest point is cut on in one move.
    if (piece.joined) {
      carried = seg.a;
    } else {
      add_piece(out, seg);
    }
  }
}

}  // namespace cncd::interp::g7x
