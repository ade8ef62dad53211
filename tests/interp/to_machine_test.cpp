// MachineTracker: program coordinates and units -> machine coordinates and units.
#include <gtest/gtest.h>

#include "cncd/interp/to_machine.hpp"

namespace cncd::interp {
namespace {

CanonCommand command(CanonKind kind, Pose pos = {}, int ivalue = 0, double value = 0) {
  CanonCommand c;
  c.kind = kind;
  c.pos = pos;
  c.ivalue = ivalue;
  c.value = value;
  return c;
}

TEST(MachineTracker, AppliesOffsetsInProgramUnitsThenConvertsUnits) {
  MachineTracker tracker(Units::mm);
  tracker.to_machine(command(CanonKind::use_length_units, {}, static_cast<int>(Units::inches)));
  tracker.to_machine(command(CanonKind::set_g5x_offset, Pose{1, 0, 0}, 1));
  tracker.to_machine(command(CanonKind::set_g92_offset, Pose{0, 1, 0}));
  tracker.to_machine(command(CanonKind::use_tool_length_offset, Pose{0, 0, 2}));
  const auto move = tracker.to_machine(command(CanonKind::straight_feed, Pose{1, 1, 1}));
  EXPECT_DOUBLE_EQ(move.pos[0], 2 * 25.4);
  EXPECT_DOUBLE_EQ(move.pos[1], 2 * 25.4);
  EXPECT_DOUBLE_EQ(move.pos[2], 3 * 25.4);
  tracker.to_machine(command(CanonKind::set_feed_rate, {}, 0, 10));
  EXPECT_DOUBLE_EQ(tracker.feed_per_minute(), 254.0);
}

TEST(MachineTracker, RotationTurnsAboutTheG5xOrigin) {
  MachineTracker tracker(Units::mm);
  tracker.to_machine(command(CanonKind::set_g5x_offset, Pose{10, 0, 0}, 1));
  tracker.to_machine(command(CanonKind::set_xy_rotation, {}, 0, 90));
  const auto move = tracker.to_machine(command(CanonKind::straight_traverse, Pose{1, 0, 0}));
  EXPECT_NEAR(move.pos[0], 10.0, 1e-12);
  EXPECT_NEAR(move.pos[1], 1.0, 1e-12);
}

TEST(MachineTracker, ArcEndAndCenterAreConverted) {
  MachineTracker tracker(Units::inches);
  CanonCommand arc = command(CanonKind::arc_feed, Pose{25.4, 0, 0});
  arc.plane = Plane::xy;
  arc.first_end = 25.4;
  arc.second_end = 0;
  arc.first_axis = 12.7;
  arc.second_axis = 0;
  arc.axis_end_point = 0;
  arc.rotation = -1;
  const auto out = tracker.to_machine(arc);
  EXPECT_DOUBLE_EQ(out.first_end, 1.0);
  EXPECT_DOUBLE_EQ(out.first_axis, 0.5);
  EXPECT_EQ(out.rotation, -1);
}

}  // namespace
}  // namespace cncd::interp
