// MotionController with its real servo thread and clock.
#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/motion/controller.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::MachineState;
using Result = motion::MotionController::EnqueueResult;

// The machine's drivers, as the daemon builds them.
std::vector<drivers::DriverInstance> drivers_of(const config::MachineConfig& config) {
  std::string error;
  auto out = drivers::make_drivers(config, error);
  EXPECT_EQ(error, "");
  return out;
}

template <typename Predicate>
bool wait_for(Predicate done, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

TEST(MotionController, RunsAMoveOnItsServoThread) {
  const auto config = small_mill();
  motion::MotionController motion(config);
  ASSERT_EQ(motion.start(drivers_of(config)), "");
  EXPECT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 1, 0, 0, 10)), Result::refused);
  EXPECT_EQ(motion.enqueue_error(), "machine is not on");
  motion.reset_estop();
  motion.machine_on();
  // Commands are applied before they return.
  EXPECT_EQ(motion.status().machine, MachineState::on);
  motion.home(0xFFFFFFFFu);
  ASSERT_TRUE(wait_for([&] {
    const auto s = motion.status();
    return s.homed[0] && s.homed[1] && s.homed[2] && s.motion == motion::MotionState::idle;
  }));
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 5, 2, -1, 50)), Result::queued);
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::traverse, 0, 0, 600)), Result::refused);
  EXPECT_NE(motion.enqueue_error().find("soft limits"), std::string::npos);
  ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 1; }));
  // Feedback trails the command by a period.
  ASSERT_TRUE(wait_for([&] { return motion.status().actual[0] == 5; }));
  const auto s = motion.status();
  EXPECT_EQ(s.commanded[0], 5);
  EXPECT_EQ(s.commanded[1], 2);
  EXPECT_EQ(s.commanded[2], -1);
  EXPECT_EQ(s.actual[0], 5);
  EXPECT_GT(s.rt.cycles, 10u);
  // Overrides are applied by the servo thread before the calls return, clamped.
  motion.set_feed_override(0.5);
  motion.set_rapid_override(7);
  EXPECT_DOUBLE_EQ(motion.status().feed_override, 0.5);
  EXPECT_DOUBLE_EQ(motion.status().rapid_override, 1.0);
  motion.stop();
  motion.stop();  // idempotent
}

TEST(MotionController, NextMoveStartsWhereAnAbortLeftTheMachine) {
  const auto config = small_mill();
  motion::MotionController motion(config);
  ASSERT_EQ(motion.start(drivers_of(config)), "");
  motion.reset_estop();
  motion.machine_on();
  motion.home(0xFFFFFFFFu);
  ASSERT_TRUE(wait_for([&] { return motion.status().homed[2]; }));
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 100, 0, 0, 50)), Result::queued);
  ASSERT_TRUE(wait_for([&] { return motion.status().commanded[0] > 5; }));
  motion.abort();
  ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 1; }));
  ASSERT_TRUE(wait_for([&] { return motion.status().motion == motion::MotionState::idle; }));
  const double stopped_at = motion.status().commanded[0];
  EXPECT_LT(stopped_at, 100);
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, stopped_at, 10, 0, 50)),
            Result::queued);
  ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 2; }));
  EXPECT_EQ(motion.status().commanded[0], stopped_at);
  EXPECT_EQ(motion.status().commanded[1], 10);
}

bool has_warning(const motion::MotionController& motion, const std::string& text) {
  for (const auto& warning : motion.start_warnings()) {
    if (warning.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(MotionController, RunsWithoutWhatTheSystemRefusesAndSaysSoOnce) {
  auto config = small_mill();
  config.cncd.rt_priority = 0;  // not a SCHED_FIFO priority: refused even for root
  config.cncd.rt_cpu = 1000;    // no such CPU
  motion::MotionController motion(config);
  ASSERT_EQ(motion.start(drivers_of(config)), "");
  EXPECT_TRUE(has_warning(motion, "SCHED_FIFO priority 0 refused")) << motion.start_warnings()[0];
  EXPECT_TRUE(has_warning(motion, "CPU 1000"));
  EXPECT_FALSE(motion.status().rt.realtime);
  motion.reset_estop();
  motion.machine_on();
  motion.home(0xFFFFFFFFu);
  ASSERT_TRUE(wait_for([&] { return motion.status().homed[0]; }));
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 2, 0, 0, 50)), Result::queued);
  ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 1; }));
  EXPECT_EQ(motion.status().commanded[0], 2);
  // Nothing about scheduling goes through the event ring as well.
  motion::Event event;
  while (motion.poll_event(event))
    EXPECT_EQ(std::string(event.text).find("SCHED_FIFO"), std::string::npos);
}

TEST(MotionController, StartsAfreshAfterStop) {
  const auto config = small_mill();
  motion::MotionController motion(config);
  for (int run = 0; run < 2; ++run) {
    ASSERT_EQ(motion.start(drivers_of(config)), "");
    EXPECT_EQ(motion.status().machine, MachineState::estop);
    EXPECT_FALSE(motion.status().homed[0]);
    motion.reset_estop();
    motion.machine_on();
    motion.home(0xFFFFFFFFu);
    ASSERT_TRUE(wait_for([&] { return motion.status().homed[0]; }));
    ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 3, 1, 0, 50)), Result::queued);
    ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 1; })) << "run " << run;
    EXPECT_EQ(motion.status().commanded[1], 1);
    motion.stop();
  }
}

TEST(MotionController, RefusesMovesWhileHoming) {
  auto config = small_mill();
  config.joints[0].home_search_vel = 100;
  config.joints[0].home_latch_vel = 10;
  config.joints[0].home_offset = 5;  // the sim's switch: about half a second of homing
  motion::MotionController motion(config);
  ASSERT_EQ(motion.start(drivers_of(config)), "");
  motion.reset_estop();
  motion.machine_on();
  motion.home(0xFFFFFFFFu);
  EXPECT_EQ(motion.status().motion, motion::MotionState::homing);
  EXPECT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 1, 0, 0, 10)), Result::refused);
  EXPECT_EQ(motion.enqueue_error(), "the machine is homing");
  ASSERT_TRUE(wait_for([&] {
    const auto s = motion.status();
    return s.homed[0] && s.homed[1] && s.homed[2] && s.motion == motion::MotionState::idle;
  }));
  EXPECT_EQ(motion.status().fault_reason[0], '\0') << motion.status().fault_reason;
  ASSERT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 1, 0, 0, 10)), Result::queued);
  ASSERT_TRUE(wait_for([&] { return motion.status().segments_done == 1; }));
  EXPECT_EQ(motion.status().commanded[0], 1);
}

TEST(MotionController, UnavailableDriverIsNotMade) {
  auto config = small_mill();
  config.joints[1].driver = "teleporter";
  std::string error;
  EXPECT_TRUE(drivers::make_drivers(config, error).empty());
  EXPECT_NE(error.find("'teleporter'"), std::string::npos) << error;
}

// Every joint needs a driver, and one only: motion refuses to start otherwise.
TEST(MotionController, AJointWithoutADriverFailsStart) {
  const auto config = small_mill();
  auto drivers = drivers_of(config);
  ASSERT_FALSE(drivers.empty());
  drivers.front().joints.pop_back();
  const int left_out = static_cast<int>(config.joints.size()) - 1;
  motion::MotionController motion(config);
  EXPECT_EQ(motion.start(std::move(drivers)),
            "joint " + std::to_string(left_out) + " has no driver");
  EXPECT_EQ(motion.enqueue(line_to(motion::Move::Kind::feed, 1, 0, 0, 10)), Result::refused);
  EXPECT_EQ(motion.status().machine, MachineState::estop);
  motion.estop();  // harmless without a servo thread

  auto twice = drivers_of(config);
  twice.front().joints.push_back(0);
  EXPECT_EQ(motion.start(std::move(twice)), "joint 0 is not a joint a driver may drive");
}

}  // namespace
}  // namespace cncd::test
