// Homing alone: its joints driven by a perfect drive simulated here (the feedback is the
// command, a home switch closes past a motor position), without a servo loop.
#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "cncd/motion/homing.hpp"
#include "machine_fixture.hpp"

namespace cncd::motion {
namespace {

constexpr double kDt = 1e-3;

struct Drive {
  std::array<double, 3> switch_at{1e9, 1e9, 1e9};  // motor position where each switch closes

  // The drive followed last period's command exactly; the switches read from there.
  void feed(JointIo& io) const {
    for (std::size_t k = 0; k < 3; ++k) {
      io.feedback[k] = io.command[k];
      io.home_switch[k] = io.command[k] + io.motor_offset[k] >= switch_at[k];
    }
  }
};

Homing::Result run(Homing& homing, JointIo& io, const Drive& drive, int max_periods = 100'000) {
  for (int n = 0; n < max_periods; ++n) {
    drive.feed(io);
    const Homing::Result r = homing.update(io);
    if (r != Homing::Result::running) return r;
  }
  return Homing::Result::running;
}

// Joint 0 searches its home switch at 20 mm/s and latches at 2 mm/s.
config::MachineConfig switch_search_mill() {
  auto config = test::small_mill();
  config.joints[0].home_search_vel = 20;
  config.joints[0].home_latch_vel = 2;
  return config;
}

TEST(HomingUnit, ImmediateHomingRenamesThePositionAndMovesToHome) {
  auto config = test::small_mill();
  config.joints[0].home_offset = 3;
  config.joints[0].home = 1;
  Homing homing(config, kDt, 0);
  JointIo io;
  io.motor_offset[0] = 0;
  io.command[0] = io.feedback[0] = 12.5;
  ASSERT_TRUE(homing.start(1u << 0, io)) << format_event(homing.fault());
  EXPECT_TRUE(homing.active());
  // Renamed at once: the motor (12.5) is now joint position 3.
  EXPECT_DOUBLE_EQ(io.command[0], 3.0);
  EXPECT_DOUBLE_EQ(io.motor_offset[0], 9.5);
  EXPECT_EQ(run(homing, io, Drive{}), Homing::Result::finished);
  EXPECT_TRUE(io.homed[0]);
  EXPECT_FALSE(io.homed[1]);
  EXPECT_DOUBLE_EQ(io.command[0], 1.0);
  EXPECT_EQ(homing.update(io), Homing::Result::idle);
  EXPECT_FALSE(homing.active());
}

TEST(HomingUnit, LatchesTheSwitchEdgeAsHomeOffset) {
  auto config = test::small_mill();
  auto& joint = config.joints[1];
  joint.home_search_vel = 20;
  joint.home_latch_vel = 2;  // same sign: back off, then latch where the switch closes
  joint.home_offset = 5;
  joint.home = 0;
  Homing homing(config, kDt, 0b111);
  JointIo io;
  Drive drive;
  drive.switch_at[1] = 30;
  ASSERT_TRUE(homing.start(1u << 1, io)) << format_event(homing.fault());
  EXPECT_EQ(run(homing, io, drive), Homing::Result::finished);
  EXPECT_TRUE(io.homed[1]);
  EXPECT_DOUBLE_EQ(io.command[1], 0.0);
  // The edge at motor 30 is joint position 5: HOME (0) is motor 25, to a latch step.
  EXPECT_NEAR(io.command[1] + io.motor_offset[1], 25.0, 2 * 2 * kDt);
}

TEST(HomingUnit, SwitchSearchWithoutASwitchIsRefused) {
  const auto config = switch_search_mill();
  Homing homing(config, kDt, 0);  // no driver reports a home switch
  JointIo io;
  EXPECT_FALSE(homing.start(1u << 0, io));
  EXPECT_NE(format_event(homing.fault()), "");
  EXPECT_FALSE(homing.active());
}

TEST(HomingUnit, AbortStopsTheSearchAndLeavesTheJointUnhomed) {
  const auto config = switch_search_mill();
  Homing homing(config, kDt, 0b111);
  JointIo io;
  const Drive drive;  // the switch is never reached
  ASSERT_TRUE(homing.start(1u << 0, io));
  for (int n = 0; n < 1000; ++n) {
    drive.feed(io);
    ASSERT_EQ(homing.update(io), Homing::Result::running);
  }
  const double moving_at = io.command[0];
  EXPECT_GT(moving_at, 0.0);
  homing.abort();
  EXPECT_TRUE(homing.stopping());
  EXPECT_EQ(run(homing, io, drive), Homing::Result::aborted);
  EXPECT_FALSE(io.homed[0]);
  // 20 mm/s stops within 20^2 / (2 * 2000) = 0.1 mm.
  EXPECT_LE(io.command[0] - moving_at, 0.1 + 1e-9);
}

TEST(HomingUnit, StopNowForgetsHomingAtOnce) {
  const auto config = switch_search_mill();
  Homing homing(config, kDt, 0b111);
  JointIo io;
  ASSERT_TRUE(homing.start(1u << 0, io));
  homing.update(io);
  homing.stop_now();
  EXPECT_FALSE(homing.active());
  EXPECT_EQ(homing.update(io), Homing::Result::idle);
}

}  // namespace
}  // namespace cncd::motion
