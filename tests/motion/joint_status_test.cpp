// Per-joint status: switch inputs, drive flags, the driver's name and soft-limit flags as the
// servo thread publishes them.
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Command;
using motion::MachineState;
using motion::Move;

// One flag of the small mill's three joints, in joint order.
std::vector<bool> flags(const motion::Status& s, bool motion::JointStatus::*flag) {
  return {s.joints[0].*flag, s.joints[1].*flag, s.joints[2].*flag};
}

TEST(JointStatus, NamesTheDriverAndFollowsTheEnable) {
  VirtualMachine m(small_mill());
  m.cycles(1);
  auto s = m.status();
  for (int j = 0; j < 3; ++j) {
    const auto& joint = s.joints[static_cast<std::size_t>(j)];
    EXPECT_STREQ(joint.driver, "recording") << "joint " << j;
    EXPECT_FALSE(joint.enabled) << "joint " << j;
  }
  EXPECT_STREQ(s.joints[3].driver, "");  // not configured
  m.ready();
  s = m.status();
  for (int j = 0; j < 3; ++j)
    EXPECT_TRUE(s.joints[static_cast<std::size_t>(j)].enabled) << "joint " << j;
  m.command(Command::Kind::off);
  EXPECT_FALSE(m.status().joints[0].enabled);
}

TEST(JointStatus, LimitSwitchesAsReadEachPeriod) {
  VirtualMachine m(small_mill());
  m.command(Command::Kind::reset_estop);  // off: a tripped switch shows without a fault
  m.sim().set_limit(1, false, true);
  m.sim().set_limit(2, true, false);
  m.cycles(1);
  auto s = m.status();
  EXPECT_EQ(flags(s, &motion::JointStatus::min_limit), (std::vector<bool>{false, false, true}));
  EXPECT_EQ(flags(s, &motion::JointStatus::max_limit), (std::vector<bool>{false, true, false}));
  EXPECT_STREQ(s.fault_reason, "");

  // On, the tripped switch latches a fault and the drives go off; the flag stays as read.
  m.sim().set_limit(2, false, false);
  m.command(Command::Kind::on);
  m.cycles(1);
  s = m.status();
  EXPECT_EQ(s.machine, MachineState::off);
  EXPECT_TRUE(s.joint_fault[1]);
  EXPECT_TRUE(s.joints[1].max_limit);
  EXPECT_FALSE(s.joints[1].enabled);
  EXPECT_FALSE(s.joints[2].min_limit);

  m.sim().set_limit(1, false, false);
  m.cycles(1);
  EXPECT_FALSE(m.status().joints[1].max_limit);
}

TEST(JointStatus, DriveFaultAndStaleFeedback) {
  VirtualMachine m(small_mill());
  m.command(Command::Kind::reset_estop);
  m.sim().set_fault(2, true);
  m.sim().set_stale(0, true);
  m.cycles(1);
  auto s = m.status();
  EXPECT_EQ(flags(s, &motion::JointStatus::stale), (std::vector<bool>{true, false, false}));
  EXPECT_EQ(flags(s, &motion::JointStatus::drive_fault), (std::vector<bool>{false, false, true}));
  m.sim().set_fault(2, false);
  m.sim().set_stale(0, false);
  m.cycles(1);
  s = m.status();
  EXPECT_FALSE(s.joints[0].stale);
  EXPECT_FALSE(s.joints[2].drive_fault);
}

TEST(JointStatus, HomeSwitchInput) {
  VirtualMachine m(small_mill());
  m.sim().set_home_switch(1, 0.0, -1);  // closed at motor positions <= 0: here
  m.cycles(1);
  auto s = m.status();
  EXPECT_FALSE(s.joints[0].home_switch);
  EXPECT_TRUE(s.joints[1].home_switch);
  m.sim().set_home_switch(1, 0.0, 0);
  m.cycles(1);
  EXPECT_FALSE(m.status().joints[1].home_switch);
}

TEST(JointStatus, AtSoftLimitOnlyOnceHomed) {
  auto config = small_mill();
  config.axes[0].min_limit = 0;  // X homes at 0, on its minimum
  config.joints[0].min_limit = 0;
  VirtualMachine m(config);
  m.cycles(1);
  EXPECT_FALSE(m.status().joints[0].at_min_soft_limit);  // there, but not homed
  m.ready();
  auto s = m.status();
  EXPECT_TRUE(s.joints[0].at_min_soft_limit);
  EXPECT_FALSE(s.joints[0].at_max_soft_limit);
  EXPECT_FALSE(s.joints[2].at_min_soft_limit);

  m.queue(line_to(Move::Kind::traverse, 10, 0, 500));
  m.run_until_idle();
  s = m.status();
  EXPECT_FALSE(s.joints[0].at_min_soft_limit);
  EXPECT_TRUE(s.joints[2].at_max_soft_limit);
  EXPECT_FALSE(s.joints[2].at_min_soft_limit);
}

}  // namespace
}  // namespace cncd::test
