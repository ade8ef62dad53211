// The plane geometry cutter compensation is built on, alone.
#include <gtest/gtest.h>

#include <numbers>

#include "comp_state.hpp"

namespace cncd::interp {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(CompGeometry, ArcSweepIsSignedByDirectionAndCountsWholeTurns) {
  const PlanePoint center{0, 0};
  EXPECT_NEAR(arc_sweep({1, 0}, center, 1, {0, 1}), kPi / 2, 1e-12);
  EXPECT_NEAR(arc_sweep({1, 0}, center, -1, {0, 1}), -3 * kPi / 2, 1e-12);
  EXPECT_NEAR(arc_sweep({1, 0}, center, 2, {0, 1}), kPi / 2 + 2 * kPi, 1e-12);
  EXPECT_NEAR(arc_sweep({1, 0}, center, 1, {1, 0}), 2 * kPi, 1e-12);  // a full circle
  EXPECT_EQ(arc_sweep({1, 0}, center, 0, {0, 1}), 0.0);
}

TEST(CompGeometry, TheToolIsInsideAnArcThatTurnsTowardItsSide) {
  EXPECT_TRUE(tool_inside_arc(CompSide::left, 1));
  EXPECT_TRUE(tool_inside_arc(CompSide::right, -1));
  EXPECT_FALSE(tool_inside_arc(CompSide::left, -1));
  EXPECT_FALSE(tool_inside_arc(CompSide::right, 2));
}

TEST(CompGeometry, PointsAlongADirection) {
  const PlanePoint p = along({1, 1}, 2, kPi / 2);
  EXPECT_NEAR(p.a, 1, 1e-12);
  EXPECT_NEAR(p.b, 3, 1e-12);
  EXPECT_NEAR(direction({0, 0}, {-1, 0}), kPi, 1e-12);
  EXPECT_NEAR(distance({0, 0}, {3, 4}), 5, 1e-12);
  const CompAxes xz = comp_axes(Plane::xz);
  EXPECT_EQ(xz.a, 2U);  // Z first, as ARC_FEED names the XZ plane
  EXPECT_EQ(xz.b, 0U);
}

}  // namespace
}  // namespace cncd::interp
