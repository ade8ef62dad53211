// Joints starting at saved positions ([TRAJ] POSITION_FILE) instead of where the drives stand.
#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;

TEST(StartPositions, JointsStartThereUnhomedAndTheMotorsStayPut) {
  VirtualMachine m(small_mill());
  motion::JointArray saved{};
  saved[0] = 12.5;
  saved[1] = -7.25;
  saved[2] = 3;
  m.loop().set_start_positions(saved);
  EXPECT_DOUBLE_EQ(m.status().commanded[0], 12.5);  // before the first cycle too
  m.cycles(1);
  auto status = m.status();
  for (int j = 0; j < 3; ++j) {
    EXPECT_DOUBLE_EQ(status.joint_commanded[static_cast<std::size_t>(j)],
                     saved[static_cast<std::size_t>(j)]);
    EXPECT_DOUBLE_EQ(status.joint_actual[static_cast<std::size_t>(j)],
                     saved[static_cast<std::size_t>(j)]);
    EXPECT_DOUBLE_EQ(status.commanded[static_cast<std::size_t>(j)],
                     saved[static_cast<std::size_t>(j)]);
    EXPECT_FALSE(status.homed[static_cast<std::size_t>(j)]);
  }
  m.command(Command::Kind::reset_estop);
  m.command(Command::Kind::on);
  m.cycles(100);
  status = m.status();
  EXPECT_EQ(status.fault_reason[0], '\0') << status.fault_reason;
  for (int j = 0; j < 3; ++j) {
    EXPECT_DOUBLE_EQ(status.joint_actual[static_cast<std::size_t>(j)],
                     saved[static_cast<std::size_t>(j)]);
    // The simulated motors were at 0 and were never told to move.
    EXPECT_DOUBLE_EQ(m.motor_position(j), 0.0);
  }
}

TEST(StartPositions, WithoutThemTheJointsStartWhereTheDrivesStand) {
  VirtualMachine m(small_mill());
  m.cycles(1);
  for (int j = 0; j < 3; ++j)
    EXPECT_DOUBLE_EQ(m.status().joint_actual[static_cast<std::size_t>(j)], 0.0);
}

}  // namespace
}  // namespace cncd::test
