// MachineTracker: program coordinates and units -> machine coordinates and units.
#include <gtest/gtest.h>

#include <variant>

#include "cncd/interp/to_machine.hpp"

namespace cncd::interp {
namespace {

CanonCommand command(CanonOp op) {
  return CanonCommand{0, std::move(op)};
}

TEST(MachineTracker, AppliesOffsetsInProgramUnitsThenConvertsUnits) {
  MachineTracker tracker(Units::mm);
  tracker.to_machine(command(UseLengthUnits{Units::inches}));
  tracker.to_machine(command(SetG5xOffset{1, Pose{1, 0, 0}}));
  tracker.to_machine(command(SetG92Offset{Pose{0, 1, 0}}));
  tracker.to_machine(command(UseToolLengthOffset{Pose{0, 0, 2}}));
  const auto move = tracker.to_machine(command(StraightFeed{Pose{1, 1, 1}}));
  const Pose& end = std::get<StraightFeed>(move.op).end;
  EXPECT_DOUBLE_EQ(end[0], 2 * 25.4);
  EXPECT_DOUBLE_EQ(end[1], 2 * 25.4);
  EXPECT_DOUBLE_EQ(end[2], 3 * 25.4);
  tracker.to_machine(command(SetFeedRate{10}));
  EXPECT_DOUBLE_EQ(tracker.feed_per_minute(), 254.0);
}

TEST(MachineTracker, RotationTurnsAboutTheG5xOrigin) {
  MachineTracker tracker(Units::mm);
  tracker.to_machine(command(SetG5xOffset{1, Pose{10, 0, 0}}));
  tracker.to_machine(command(SetXyRotation{90}));
  const auto move = tracker.to_machine(command(StraightTraverse{Pose{1, 0, 0}}));
  const Pose& end = std::get<StraightTraverse>(move.op).end;
  EXPECT_NEAR(end[0], 10.0, 1e-12);
  EXPECT_NEAR(end[1], 1.0, 1e-12);
}

TEST(MachineTracker, ArcEndAndCenterAreConverted) {
  MachineTracker tracker(Units::inches);
  ArcFeed arc;
  arc.plane = Plane::xy;
  arc.first_end = 25.4;
  arc.second_end = 0;
  arc.first_axis = 12.7;
  arc.second_axis = 0;
  arc.axis_end_point = 0;
  arc.rotation = -1;
  const auto out = std::get<ArcFeed>(tracker.to_machine(command(arc)).op);
  EXPECT_DOUBLE_EQ(out.first_end, 1.0);
  EXPECT_DOUBLE_EQ(out.first_axis, 0.5);
  EXPECT_EQ(out.rotation, -1);
}

}  // namespace
}  // namespace cncd::interp
