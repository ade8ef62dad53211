// G2/G3: center (IJK) and radius (R) formats, full circles, P turns and helices, with
// LinuxCNC's tolerances and error messages.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

struct ArcPlane {
  std::size_t first;
  std::size_t second;
  std::size_t normal;
  char first_offset;    // center offset letter along `first`
  char second_offset;   // along `second`
  char foreign_offset;  // the offset letter that does not belong to the plane
  const char* name;
};

ArcPlane arc_plane(Plane plane) {
  switch (plane) {
    case Plane::xz:
      return {kZ, kX, kY, 'k', 'i', 'j', "xz"};
    case Plane::yz:
      return {kY, kZ, kX, 'j', 'k', 'i', "yz"};
    case Plane::xy:
    default:
      return {kX, kY, kZ, 'i', 'j', 'k', "xy"};
  }
}

// LinuxCNC's limits: a center-format arc may miss its radius by this much, or by 0.1 % of
// the larger radius but never by more than 100 times this much (the motion planner runs what
// passes as a spiral); a radius-format arc may be this much too short to reach its end point.
constexpr double kCenterToleranceMm = 0.028284271247461905;  // 0.02 * sqrt(2)
constexpr double kCenterToleranceInch = 0.0028284271247461905;
constexpr double kCenterRelativeTolerance = 0.001;
constexpr double kCenterToleranceCap = 100.0;
constexpr double kRadiusToleranceInch = 0.00005;

std::string format(const char* pattern, double a, double b) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

}  // namespace

void Interpreter::Impl::arc(bool clockwise, const Pose& end) {
  // LinuxCNC's arcs run in the XYZ planes only.
  if (modal_.plane == Plane::uv || modal_.plane == Plane::vw || modal_.plane == Plane::uw) {
    fail("Cannot do an arc in planes G17.1, G18.1, or G19.1");
  }
  const ArcPlane axes = arc_plane(modal_.plane);
  const bool radius_format = block_.has('r');
  const bool has_offsets = block_.has(axes.first_offset) || block_.has(axes.second_offset);

  if (block_.has(axes.foreign_offset)) {
    fail(std::string(1, static_cast<char>(std::toupper(axes.foreign_offset))) +
         " word given for arc in " + axes.name + " plane");
  }
  if (!radius_format && !has_offsets) fail("R i j k words all missing for arc");
  if (radius_format && has_offsets) fail("Mixed radius ijk format for arc");
  int turns = 1;
  if (block_.has('p')) {
    const double p = block_.get('p');
    if (p != std::floor(p)) fail("P value not an integer with M19 G2 or G3", block_.col('p'));
    if (p < 1.0) fail("P value should be 1 or greater with G2 or G3", block_.col('p'));
    turns = to_int(p);
  }
  if (radius_format) {
    // The plane letters in order (X before Y before Z), as LinuxCNC names them.
    const char letter1 = kAxisLetters[axes.first];
    const char letter2 = kAxisLetters[axes.second];
    const bool first_is_later = axes.first > axes.second;
    const char low = first_is_later ? letter2 : letter1;
    const char high = first_is_later ? letter1 : letter2;
    if (!block_.has(low) && !block_.has(high)) {
      fail(std::string(1, static_cast<char>(std::toupper(low))) + " and " + high +
           " words missing for arc in " + axes.name + " plane");
    }
  }
  if (comp_.active()) {
    Comp::comp_arc(*this, clockwise, end, turns);
    return;
  }
  double center1 = 0;
  double center2 = 0;
  arc_center(clockwise, {pos_[axes.first], pos_[axes.second]}, {end[axes.first], end[axes.second]},
             center1, center2);
  if (modal_.feed_mode == FeedMode::inverse_time) {
    arc_feed_rate(clockwise, turns, pos_, {center1, center2}, end);
  }
  ArcFeed command;
  command.plane = modal_.plane;
  command.set_end(end);
  command.first_axis = center1;
  command.second_axis = center2;
  command.rotation = clockwise ? -turns : turns;
  emit(command);
  pos_ = end;
}

// Inverse time: the rate that makes the arc from `start` around `center` take 1/F minutes.
void Interpreter::Impl::arc_feed_rate(bool clockwise, int turns, const Pose& start,
                                      PlanePoint center, const Pose& end) {
  const ArcPlane axes = arc_plane(modal_.plane);
  const double start1 = start[axes.first];
  const double start2 = start[axes.second];
  const double radius = std::hypot(start1 - center.a, start2 - center.b);
  const double a0 = std::atan2(start2 - center.b, start1 - center.a);
  const double a1 = std::atan2(end[axes.second] - center.b, end[axes.first] - center.a);
  double sweep = clockwise ? a0 - a1 : a1 - a0;
  if (sweep <= 1e-12) sweep += 2.0 * std::numbers::pi;
  sweep += 2.0 * std::numbers::pi * (turns - 1);
  set_inverse_time_rate(std::hypot(radius * sweep, end[axes.normal] - start[axes.normal]));
}

// The center of the arc from `start` to `end` (plane coordinates) the block's R or I J K
// words give, with LinuxCNC's checks and messages.
void Interpreter::Impl::arc_center(bool clockwise, PlanePoint start, PlanePoint end,
                                   double& center1, double& center2) const {
  const ArcPlane axes = arc_plane(modal_.plane);
  const double start1 = start.a;
  const double start2 = start.b;
  const double end1 = end.a;
  const double end2 = end.b;
  const char letter1 = static_cast<char>(std::toupper(kAxisLetters[axes.first]));
  const char letter2 = static_cast<char>(std::toupper(kAxisLetters[axes.second]));
  const bool inches = modal_.units == Units::inches;
  if (block_.has('r')) {
    const double radius = block_.get('r');
    if (end1 == start1 && end2 == start2) fail("Current point same as end point of arc");
    const double abs_radius = std::fabs(radius);
    const double mid1 = (end1 + start1) / 2.0;
    const double mid2 = (end2 + start2) / 2.0;
    double half = std::hypot(mid1 - end1, mid2 - end2);
    const double tolerance = inches ? kRadiusToleranceInch : kRadiusToleranceInch * 25.4;
    if (half - abs_radius > tolerance) fail("Arc radius too small to reach end point");
    if (half / abs_radius > 1.0 - 1e-12) half = abs_radius;  // a semicircle, give or take
    // The center is right of the chord for a clockwise minor arc, left for a counterclockwise
    // one; a negative R asks for the major arc, on the other side. Worked out as LinuxCNC
    // does, to its last bit.
    const bool right = clockwise != (radius < 0.0);
    const long double chord_angle = std::atan2(end2 - start2, end1 - start1);
    const long double quarter = 1.57079632679489661923132169163975144L;
    const auto theta = static_cast<double>(right ? chord_angle - quarter : chord_angle + quarter);
    const double offset = abs_radius * std::cos(std::asin(half / abs_radius));
    center1 = mid1 + offset * std::cos(theta);
    center2 = mid2 + offset * std::sin(theta);
  } else {
    const double o1 = block_.has(axes.first_offset) ? block_.get(axes.first_offset) : 0.0;
    const double o2 = block_.has(axes.second_offset) ? block_.get(axes.second_offset) : 0.0;
    center1 = modal_.arc_incremental ? start1 + o1 : o1;
    center2 = modal_.arc_incremental ? start2 + o2 : o2;
    const double r1 = std::hypot(start1 - center1, start2 - center2);
    const double r2 = std::hypot(end1 - center1, end2 - center2);
    auto where = [&]() {
      return std::string(" start=(") + letter1 + format("%.4f,", start1, 0) + letter2 +
             format("%.4f) center=(", start2, 0) + letter1 + format("%.4f,", center1, 0) + letter2 +
             format("%.4f) end=(", center2, 0) + letter1 + format("%.4f,", end1, 0) + letter2 +
             format("%.4f)", end2, 0) + format(" r1=%.4f r2=%.4f", r1, r2);
    };
    if (r1 == 0.0 || r2 == 0.0) fail("Zero-radius arc:" + where());
    const double abs_err = std::fabs(r1 - r2);
    const double rel_err = abs_err / std::max(r1, r2);
    const double tolerance = inches ? kCenterToleranceInch : kCenterToleranceMm;
    if (abs_err > kCenterToleranceCap * tolerance ||
        (abs_err > tolerance && rel_err > kCenterRelativeTolerance)) {
      fail("Radius to end of arc differs from radius to start:" + where() +
           format(" abs_err=%.4g rel_err=%.4f%%", abs_err, rel_err * 100.0));
    }
  }
}

}  // namespace cncd::interp
