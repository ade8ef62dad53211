// G5 (cubic spline), G5.1 (quadratic spline) and G5.2 .. G5.3 (NURBS), with rs274's checks
// and wording. rs274 keeps the motion mode of the move before a G5 or G5.1 (they are one-block
// moves), gathers G5.2 points until G5.3 and leaves no motion mode after it.
#include <algorithm>
#include <cstdio>
#include <string>

#include "cncd/interp/nurbs.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

constexpr int kDefaultOrder = 3;  // G5.2 without L, and the least order rs274 uses

}  // namespace

void Interpreter::Impl::do_spline(int code) {
  const bool inverse_time = modal_.feed_mode == FeedMode::inverse_time;
  if (inverse_time && !block_.has('f')) fail("F word missing with inverse time arc move");
  if (!inverse_time && modal_.feed_rate == 0.0) fail("Cannot make arc with zero feed rate");
  if (modal_.plane != Plane::xy) fail("Splines must be in the XY plane");
  for (const char letter : {'z', 'a', 'b', 'c', 'u', 'v', 'w'}) {
    if (block_.has(letter)) fail("Splines may not have motion in Z, A, B, or C");
  }
  const bool has_i = block_.has('i');
  const bool has_j = block_.has('j');
  NurbsFeed curve;
  const Pose start = pos_;
  const Pose end = target_from_words();
  auto offset = [&](double dx, double dy, const Pose& from) {
    Pose p = from;
    p[kX] += dx;
    p[kY] += dy;
    return p;
  };
  curve.points.push_back(start);
  if (code == 50) {
    if (has_i != has_j) fail("Must specify both I and J, or neither");
    if (!block_.has('p') || !block_.has('q')) fail("Must specify both P and Q with G5");
    // Without I and J the curve leaves along the direction the last G5 ended in.
    const double i = has_i ? block_.get('i') : -spline_.last_p;
    const double j = has_j ? block_.get('j') : -spline_.last_q;
    spline_.last_p = block_.get('p');
    spline_.last_q = block_.get('q');
    curve.points.push_back(offset(i, j, start));
    curve.points.push_back(offset(spline_.last_p, spline_.last_q, end));
  } else {
    if (!has_i || !has_j) fail("Must specify both I and J with G5.1");
    curve.points.push_back(offset(block_.get('i'), block_.get('j'), start));
  }
  curve.points.push_back(end);
  curve.weights.assign(curve.points.size(), 1.0);
  curve.order = static_cast<int>(curve.points.size());
  if (inverse_time) {
    curve.inverse_time_feed = NurbsCurve(curve).length() * block_.get('f');
  }
  emit(curve);
  pos_ = end;
}

// A line of G5.2: the first one (the motion mode was not G5.2, or a G5.3 closed the last
// curve) starts the curve at the current point, whose weight P gives when X and Y are absent;
// each later one adds a point, with its weight P.
void Interpreter::Impl::do_nurbs_point() {
  const bool first = !spline_.open || previous_motion_ != 52;
  const bool has_x = block_.has('x');
  const bool has_y = block_.has('y');
  if (first) spline_.inverse_f = 0;
  if (block_.has('f')) spline_.inverse_f = block_.get('f');
  if (first) {
    if (modal_.feed_mode != FeedMode::inverse_time && modal_.feed_rate == 0.0) {
      fail("Cannot make a NURBS with 0 feedrate");
    }
    spline_.open = true;
    spline_.nurbs = NurbsFeed{};
    spline_.nurbs.order = kDefaultOrder;
    spline_.nurbs.points.push_back(pos_);
    // rs274 takes any weight on this line; one of 0 or below leaves the curve undefined.
    const double weight = block_.has('p') ? block_.get('p') : 1.0;
    if (weight <= 0.0) fail("Must specify positive weight P for every Control Point");
    spline_.nurbs.weights.push_back(has_x || has_y ? 1.0 : weight);
    if (!has_x && !has_y) {
      if (block_.has('l')) spline_.nurbs.order = to_int(block_.get('l'));
      return;
    }
  }
  if (!has_x || !has_y) fail("You must specify both X and Y coordinates for Control Points");
  if (!first && (!block_.has('p') || block_.get('p') <= 0.0)) {
    fail("Must specify positive weight P for every Control Point");
  }
  if (block_.has('l')) spline_.nurbs.order = to_int(block_.get('l'));
  // Incremental points count from where the curve starts: the position moves at G5.3.
  Pose point = pos_;
  const Pose target = target_from_words();
  point[kX] = target[kX];
  point[kY] = target[kY];
  spline_.nurbs.points.push_back(point);
  spline_.nurbs.weights.push_back(block_.has('p') ? block_.get('p') : 1.0);
}

void Interpreter::Impl::close_nurbs() {
  if (modal_.motion != 52 || !spline_.open) fail("Cannot use G5.3 without G5.2 first");
  const int motion = block_.g_code(GGroup::motion);
  if (motion >= 0 && motion != 52) {
    fail("Between G5.2 and G5.3 codes, only additional G5.2 codes are allowed.");
  }
  NurbsFeed curve = std::move(spline_.nurbs);
  spline_.open = false;
  spline_.nurbs = NurbsFeed{};
  curve.order = std::max(curve.order, kDefaultOrder);
  if (static_cast<int>(curve.points.size()) < curve.order) {
    char text[96];
    std::snprintf(text, sizeof text,
                  "You must specify a number of control points at least equal to the order L = %d",
                  curve.order);
    fail(text);
  }
  // G93: the last F among the curve's lines gives its time; without one it runs at the feed
  // in force.
  if (block_.has('f')) spline_.inverse_f = block_.get('f');
  if (modal_.feed_mode == FeedMode::inverse_time && spline_.inverse_f > 0.0) {
    curve.inverse_time_feed = NurbsCurve(curve).length() * spline_.inverse_f;
  }
  pos_ = curve.points.back();
  emit(std::move(curve));
}

}  // namespace cncd::interp
