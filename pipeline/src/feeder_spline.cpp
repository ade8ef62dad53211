// Splines (G5, G5.1, G5.2 .. G5.3) as straight feed moves that the look-ahead plans and blends
// like any others.
#include <algorithm>

#include "cncd/interp/nurbs.hpp"
#include "cncd/pipeline/feeder.hpp"

namespace cncd::pipeline {
namespace {

// The pieces stay within this distance of the curve (mm). The planner's blend at a joint of
// two pieces (G64 without P) rounds it by at most about the same amount toward the chord's
// side, so the path the tool follows stays within twice this, 0.001 mm, of the true curve.
constexpr double kSplineToleranceMm = 0.0005;

}  // namespace

void ProgramFeeder::queue_spline(const interp::NurbsFeed& spline, int line) {
  if (spline.points.size() < 2 || static_cast<int>(spline.points.size()) < spline.order ||
      spline.weights.size() != spline.points.size())
    return;  // the interpreter never emits one
  const double mm_per_unit = tracker_.machine_units() == interp::Units::inches ? 25.4 : 1.0;
  const interp::NurbsCurve curve(spline);
  // G93 gives the whole curve its time: each piece runs at the feed that keeps it.
  const bool inverse_time = spline.inverse_time_feed > 0;
  const double feed = inverse_time ? spline.inverse_time_feed / 60.0 : feed_per_second();
  bool first = true;
  for (const interp::Pose& point : curve.polyline(kSplineToleranceMm / mm_per_unit)) {
    motion::Move move;
    move.line = line;
    move.kind = motion::Move::Kind::feed;
    std::copy(point.begin(), point.end(), move.end.begin());
    move.feed = feed;
    if (per_revolution_ && !inverse_time) move.feed_per_rev = tracker_.feed_per_minute();
    begin_move(move, line);
    // The curve has no corners: its pieces always blend into each other, even in G61, while
    // the joints with the moves before and after it follow the path mode in force.
    move.path_mode = first ? path_mode_ : motion::Move::PathMode::blend;
    move.tolerance = tolerance_;
    move.merge_tolerance = path_mode_ == motion::Move::PathMode::blend ? merge_tolerance_ : 0.0;
    pending_.push_back(move);
    first = false;
  }
}

}  // namespace cncd::pipeline
