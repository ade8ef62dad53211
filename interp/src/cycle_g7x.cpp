// LinuxCNC's lathe cycles G70 (finishing), G71 and G72 (roughing along Z and along X, .1
// leaving pockets out, .2 without roughing passes). The cycle moves to its start point, runs
// the profile subroutine named by Q while keeping its moves instead of sending them, and works
// out its passes when that subroutine returns.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "g7x_profile.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

struct G7xRun {
  int code = 0;
  double d = 0, e = 0, i = 1, r = 0.5;
  double passes = 1;  // G70's P, fractions kept
  Pose start{};
  std::size_t depth = 0;  // the call level of the profile subroutine
  // The profile's moves in (x, z): u = x, v = z; an arc's ccw turns from +X toward +Z.
  g7x::Path moves;
  g7x::Pt last;
  double last_a = 0;  // A: a move that changes it asks for the corner at its end rounded by |A|
  // The cycle's frame: u along X (G70, G71) or Z (G72), each axis turned so that the profile
  // starts below the start point and runs toward -v.
  bool swap = false;
  double su = 1, sv = 1;

  g7x::Pt to_frame(g7x::Pt xz) const {
    const double a = swap ? xz.v : xz.u;
    const double b = swap ? xz.u : xz.v;
    return {su * a, sv * b};
  }
  g7x::Pt to_xz(g7x::Pt uv) const {
    const double a = uv.u * su;
    const double b = uv.v * sv;
    return swap ? g7x::Pt{b, a} : g7x::Pt{a, b};
  }
  // Whether turning one way in the frame is turning the other way in (x, z).
  bool flips() const { return swap != ((su < 0) != (sv < 0)); }
};

namespace {

bool is_g7x(int code) {
  return code == 700 || (code >= 710 && code <= 722 && code % 10 <= 2);
}

std::string code_name(int code) {
  char text[16];
  std::snprintf(text, sizeof text, "G%d.%d", code / 10, code % 10);
  return text;
}

}  // namespace

bool Interpreter::Impl::is_g7x_code(int code) {
  return is_g7x(code);
}

void Interpreter::Impl::do_g7x(int code) {
  const std::string name = code_name(code);
  if (!block_.has('q')) fail("G7x.x  requires a Q word");
  if (reading_g7x_profile()) fail(name + " cannot be used in the profile of another G7x cycle");
  if (modal_.plane != Plane::xz) fail(name + " can only be used in XZ plane (G18)");
  // rs274 runs G70 through cutter compensation; here it is refused like G71 and G72 rather
  // than run on a profile the compensation has already moved.
  if (comp_.on()) fail(name + " cannot be used with cutter compensation enabled");
  auto run = std::make_shared<G7xRun>();
  run->code = code;
  if (block_.has('d')) run->d = block_.get('d');
  if (block_.has('e')) run->e = block_.get('e');
  if (block_.has('i')) run->i = block_.get('i');
  if (block_.has('r')) run->r = block_.get('r');
  if (block_.has('p')) run->passes = block_.get('p');
  run->start = target_from_words();
  emit_straight(StraightKind::traverse, run->start);
  run->last = {run->start[kX], run->start[kZ]};
  run->last_a = run->start[kA];
  block_.o_name = std::to_string(to_int(block_.get('q')));
  block_.call_args.clear();
  do_call();
  calls_.back().g7x = true;
  run->depth = calls_.size();
  g7x_ = std::move(run);
}

bool Interpreter::Impl::reading_g7x_profile() const {
  return g7x_ && calls_.size() >= g7x_->depth;
}

bool Interpreter::Impl::g7x_capture(const CanonCommand& command) {
  if (!reading_g7x_profile()) return false;
  G7xRun& run = *g7x_;
  g7x::Seg seg;
  seg.a = run.last;
  Pose end{};
  if (const auto* t = std::get_if<StraightTraverse>(&command.op)) {
    end = t->end;
  } else if (const auto* f = std::get_if<StraightFeed>(&command.op)) {
    end = f->end;
  } else if (const auto* a = std::get_if<ArcFeed>(&command.op)) {
    end = a->end();
    const Pose center = a->center();
    seg.arc = true;
    seg.c = {center[kX], center[kZ]};
    seg.ccw = a->rotation < 0;  // ARC_FEED turns in (Z, X)
  } else {
    return false;
  }
  seg.b = {end[kX], end[kZ]};
  if (end[kA] != run.last_a) seg.round = std::fabs(end[kA]);
  run.last_a = end[kA];
  run.moves.push_back(seg);
  run.last = seg.b;
  return true;
}

void Interpreter::Impl::emit_g7x_move(const G7xRun& run, const g7x::Move& move) {
  // Axes other than X and Z stay where the cycle started, whatever the profile did with them.
  const g7x::Pt to = run.to_xz(move.seg.b);
  Pose end = run.start;
  end[kX] = to.u;
  end[kZ] = to.v;
  // The profile's own moves were not checked for a feed rate; the cycle's are.
  if (move.kind != g7x::Move::Kind::traverse && modal_.feed_rate == 0.0 &&
      modal_.feed_mode != FeedMode::inverse_time) {
    fail("Cannot do g1 with zero feed rate");
  }
  if (move.kind != g7x::Move::Kind::arc) {
    emit_straight(move.kind == g7x::Move::Kind::feed ? StraightKind::feed : StraightKind::traverse,
                  end);
    return;
  }
  const g7x::Pt center = run.to_xz(move.seg.c);
  ArcFeed command;
  command.plane = Plane::xz;
  command.set_end(end);
  command.first_axis = center.v;
  command.second_axis = center.u;
  const bool ccw_xz = move.seg.ccw != run.flips();
  command.rotation = ccw_xz ? -1 : 1;
  emit(command);
  pos_ = end;
}

// The subroutine has returned: the profile is complete and the cycle runs.
void Interpreter::Impl::finish_g7x() {
  const std::shared_ptr<G7xRun> owned = std::move(g7x_);
  G7xRun& run = *owned;
  const int family = run.code / 10;  // 70, 71, 72
  const int variant = run.code % 10;
  if (family != 70 && run.i <= 0) fail("G7X error: I must be greater than zero.");
  // Leave out moves of no length; the first move takes the tool to where the profile starts.
  g7x::Path raw;
  for (const g7x::Seg& seg : run.moves) {
    if (std::hypot(seg.b.u - seg.a.u, seg.b.v - seg.a.v) > g7x::kEps) raw.push_back(seg);
  }
  // A profile of one move or none cuts nothing; the tool stays where the subroutine left it.
  if (raw.size() < 2) return;
  const g7x::Pt s_xz{run.start[kX], run.start[kZ]};
  // The profile in the frame of G71 (swap false) or G72, turned to the profile's quadrant;
  // empty when it turns back along the passes somewhere.
  auto frame_profile = [&](bool swap) {
    run.swap = swap;
    run.su = run.sv = 1;
    const g7x::Pt s0 = run.to_frame(s_xz);
    const g7x::Pt p0 = run.to_frame(raw.front().b);
    const g7x::Pt end0 = run.to_frame(raw.back().b);
    run.su = p0.u <= s0.u ? 1 : -1;
    run.sv = end0.v <= p0.v ? 1 : -1;
    g7x::Path path;
    for (std::size_t k = 1; k < raw.size(); ++k) {
      g7x::Seg seg = raw[k];
      seg.a = run.to_frame(seg.a);
      seg.b = run.to_frame(seg.b);
      seg.c = run.to_frame(seg.c);
      seg.ccw = seg.ccw != run.flips();
      path.push_back(seg);
    }
    path = g7x::round_corners(path);
    for (const g7x::Seg& seg : path) {
      if (!g7x::v_never_rises(seg)) return g7x::Path{};
    }
    return path;
  };
  // G70 takes G71's frame, or G72's when the profile turns back along Z.
  g7x::Path profile = frame_profile(family == 72);
  if (profile.empty() && family == 70) profile = frame_profile(true);
  if (profile.empty()) fail("G7X error: Not monotonic");
  const g7x::Pt s = run.to_frame(s_xz);
  // The roughing cycles carry the profile on up to the start point's level; G70 ends with it.
  auto path_at = [&](double distance) {
    g7x::Path path = g7x::offset_path(profile, distance);
    const g7x::Pt end = path.back().b;
    if (family != 70 && end.u < s.u - g7x::kEps) path.push_back(g7x::line(end, {s.u, end.v}));
    return path;
  };
  g7x::Moves moves;
  // The tool enters level with the start point or with the profile's first point (before its
  // offset), whichever is further up the passes.
  auto approach = [&]() {
    const g7x::Pt entry{s.u, std::fmax(s.v, profile.front().a.v)};
    moves.push_back({g7x::Move::Kind::traverse, g7x::line({}, entry)});
    return entry;
  };
  if (family == 70) {
    // Whole passes, the last at E, each (D - E) / P nearer than the one before.
    const int count = to_int(run.passes);
    for (int pass = 1; pass <= count; ++pass) {
      const double distance = run.e + (run.d - run.e) * (count - pass) / run.passes;
      const g7x::Path path = path_at(distance);
      approach();
      moves.push_back({g7x::Move::Kind::traverse, g7x::line({}, path.front().a)});
      g7x::follow(path, g7x::Follow::plain, run.i, run.r, NAN, moves);
    }
  } else {
    const g7x::Path path = path_at(run.d);
    const g7x::Pt entry = approach();
    if (variant != 2) g7x::rough(path, entry, run.i, run.r, moves);
    moves.push_back({g7x::Move::Kind::traverse, g7x::line({}, path.front().a)});
    const auto how = variant == 1 ? g7x::Follow::monotonic : g7x::Follow::pockets;
    // After roughing passes the pockets are cut on the same levels; without them, from the
    // top of each pocket.
    g7x::follow(path, how, run.i, run.r, variant == 2 ? NAN : s.u, moves);
  }
  for (const g7x::Move& move : moves)
    emit_g7x_move(run, move);
}

}  // namespace cncd::interp
