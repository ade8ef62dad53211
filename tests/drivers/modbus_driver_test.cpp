// The modbus driver end to end over loopback TCP (and RTU on a pseudo-terminal pair) against
// real libmodbus servers: the simulated drives of cncd-drive-sim, run in-process.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/drivers/drive_sim.hpp"
#include "cncd/drivers/fault_reason.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "test_util.hpp"

namespace cncd::test {
namespace {

using drivers::DriveSim;
using drivers::DriveSimOptions;
using drivers::JointCommand;
using drivers::JointFeedback;
using drivers::ModbusDriver;

std::string bus_section(const std::string& transport_keys, int timeout_ms = 40) {
  return "[MODBUS_0]\n" + transport_keys + "TIMEOUT_MS = " + std::to_string(timeout_ms) +
         "\nUPDATE_PERIOD_MS = 5\nRETRIES = 1\n";
}

// The simulated drives serve at real-time priority where permitted, as drives with processors
// of their own: on a busy machine, ordinary threads would answer after the bus timeout.
constexpr int kSimPriority = 60;

constexpr const char* kJointKeys = "DRIVER = modbus\nMODBUS = 0\nSLAVE = 1{j}\nSCALE = 1000\n";

class ModbusDriverTest : public ::testing::Test {
 protected:
  void start_sim(int port = 0) {
    DriveSimOptions options;
    options.port = port;
    options.first_slave = 10;
    options.drives = 2;
    options.lag_s = 0;
    options.rt_priority = kSimPriority;
    sim_ = std::make_unique<DriveSim>(options);
    ASSERT_EQ(sim_->start(), "");
  }
  void start_driver() {
    loaded_ = load_machine(dir_, 2, kJointKeys,
                           bus_section("TRANSPORT = tcp\nHOST = 127.0.0.1\nPORT = " +
                                       std::to_string(sim_->port()) + "\n"));
    ASSERT_TRUE(loaded_.ok());
    ASSERT_EQ(driver_.configure(*loaded_.config, {0, 1}), "");
    driver_.enable();
  }
  // Plays the servo thread for `ms` periods of 1 ms; returns the last feedback.
  void servo(int ms, double x, double y, bool enable) {
    for (int i = 0; i < ms; ++i) {
      driver_.read(feedback_, 2);
      JointCommand c[2] = {{x, 0, enable}, {y, 0, enable}};
      driver_.write(c, 2);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    driver_.read(feedback_, 2);
  }
  // Plays the servo thread until `done` holds, for at most `ms` periods (a loaded machine can
  // keep the bus thread waiting for tens of milliseconds); returns whether it held.
  template <typename Done>
  bool servo_until(Done done, int ms, double x, double y, bool enable) {
    for (int i = 0; i < ms && !done(); ++i)
      servo(1, x, y, enable);
    return done();
  }
  // Runs both drives at (x, y), then sets drive 11's fault bit; whether the driver reports it
  // within 2000 periods.
  bool run_until_drive_11_faults(double x, double y) {
    start_sim();
    start_driver();
    servo(30, x, y, true);
    sim_->set_fault(11, true);
    return servo_until([&] { return feedback_[1].fault; }, 2000, x, y, true);
  }
  bool faulted(int joint) const { return feedback_[joint].fault || feedback_[joint].stale; }
  std::string reason() const {
    char text[drivers::kFaultReasonSize];
    driver_.fault_reason(text, sizeof text);
    return text;
  }

  TempDir dir_;
  config::LoadResult loaded_;
  std::unique_ptr<DriveSim> sim_;
  ModbusDriver driver_;
  JointFeedback feedback_[2];
};

TEST_F(ModbusDriverTest, SetpointsArriveAsRegisterCountsAndPositionsComeBack) {
  start_sim();
  start_driver();
  servo(20, 0, 0, false);
  EXPECT_FALSE(faulted(0) || faulted(1)) << reason();
  servo(60, 1.234, -0.5, true);
  EXPECT_EQ(sim_->target(10), 1234);
  EXPECT_EQ(sim_->target(11), -500);
  EXPECT_EQ(sim_->control(10) & 1u, 1u);
  EXPECT_DOUBLE_EQ(feedback_[0].position, 1.234);
  EXPECT_DOUBLE_EQ(feedback_[1].position, -0.5);
  EXPECT_FALSE(faulted(0) || faulted(1)) << reason();
  EXPECT_EQ(reason(), "");
  servo(20, 1.234, -0.5, false);
  EXPECT_EQ(sim_->control(10) & 1u, 0u);
}

TEST_F(ModbusDriverTest, AReadbackNamesTheCycleOfTheSetpointItAnswers) {
  start_sim();  // no lag: a drive stands on its target by the time it is read back
  start_driver();
  int answered = 0;
  std::uint64_t most_late = 0;
  std::uint64_t last[2] = {0, 0};
  std::uint64_t before_last[2] = {0, 0};
  std::uint64_t last_previous[2] = {0, 0};
  int seen_previous = 0;
  for (std::uint64_t cycle = 1; cycle <= 300; ++cycle) {
    driver_.read(feedback_, 2);
    for (int j = 0; j < 2; ++j) {
      const std::uint64_t named = feedback_[j].command_cycle;
      // No setpoint has gone out yet, or a fault (a write that timed out may still have
      // reached the drive).
      if (named == 0 || faulted(j)) continue;
      EXPECT_LT(named, cycle) << "a command not written yet";
      EXPECT_GE(named, last[j]);
      // The setpoint the drive had an update period before: an older one, or the same one
      // when this loop was held up for longer than that (a loaded machine).
      const std::uint64_t previous = feedback_[j].previous_cycle;
      EXPECT_LE(previous, named);
      EXPECT_GE(previous, last_previous[j]);
      last_previous[j] = previous;
      // Exchanges every 5 ms: mostly the one of the exchange before (or the one before that,
      // when this exchange woke up a little earlier than the last).
      if (named != last[j]) {
        seen_previous += previous != 0 && (previous == last[j] || previous == before_last[j]);
        before_last[j] = last[j];
      }
      last[j] = named;
      most_late = std::max(most_late, cycle - 1 - named);
      // Every setpoint is its own cycle in counts (negated for joint 1): the position read
      // back is the one of the setpoint the readback names.
      const double sign = j == 0 ? 1.0 : -1.0;
      EXPECT_DOUBLE_EQ(feedback_[j].position, sign * static_cast<double>(named) / 1000)
          << "joint " << j << " at cycle " << cycle;
      ++answered;
    }
    const double counts = static_cast<double>(cycle);
    const JointCommand c[2] = {{counts / 1000, 0, true, cycle}, {-counts / 1000, 0, true, cycle}};
    driver_.write(c, 2);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GT(answered, 400);
  EXPECT_GT(seen_previous, 20);  // about 2 x 60 updates
  // Updated every 5 ms, the readbacks answer setpoints several servo periods old.
  EXPECT_GE(most_late, 3u);
  EXPECT_FALSE(faulted(0) || faulted(1)) << reason();
  // Stale feedback older than 5 x 5 + 2 x 40 ms, answering setpoints up to 5 ms older.
  EXPECT_EQ(driver_.feedback_deadline_ns(), 110'000'000);
}

TEST_F(ModbusDriverTest, KilledDriveLatchesAFaultAndWorksAgainOnlyAfterReset) {
  start_sim();
  const int port = sim_->port();
  start_driver();
  servo(40, 0.1, 0.2, true);
  ASSERT_FALSE(faulted(0)) << reason();
  EXPECT_EQ(driver_.exchange_errors(), 0u) << "a healthy bus counts no error";
  sim_.reset();  // power cut
  int periods = 0;
  while (!faulted(0) && periods < 500) {
    servo(1, 0.1, 0.2, true);
    ++periods;
  }
  EXPECT_TRUE(feedback_[0].fault);
  EXPECT_LT(periods, 100) << "a dead drive must fault within a few update periods";
  EXPECT_NE(reason().find("slave 1"), std::string::npos) << reason();
  // The failed request, and each failed reconnect since.
  const std::uint64_t dead = driver_.exchange_errors();
  EXPECT_GT(dead, 0u);
  servo(50, 0.1, 0.2, true);
  EXPECT_GT(driver_.exchange_errors(), dead) << "reconnects to a dead drive count too";

  start_sim(port);  // the drive comes back; the bus reconnects by itself
  servo(100, 0.3, 0.4, true);
  EXPECT_EQ(sim_->target_writes(10), 0u) << "no setpoints before an explicit reset";
  EXPECT_EQ(sim_->control(10) & 1u, 0u);
  EXPECT_TRUE(feedback_[0].fault) << "the fault stays latched";

  servo(20, 0.3, 0.4, false);  // machine off ...
  servo(60, 0.3, 0.4, true);   // ... and on again
  EXPECT_FALSE(faulted(0) || faulted(1)) << reason();
  EXPECT_EQ(sim_->target(10), 300);
  EXPECT_EQ(sim_->target(11), 400);
  EXPECT_EQ(reason(), "");
}

TEST_F(ModbusDriverTest, DriveFaultBitLatchesAndIsResetThroughTheControlWord) {
  EXPECT_TRUE(run_until_drive_11_faults(0, 0));
  EXPECT_FALSE(feedback_[0].fault);
  EXPECT_NE(reason().find("slave 11 (joint 1): drive reports a fault"), std::string::npos)
      << reason();
  sim_->set_fault(11, false);
  servo(20, 0, 0, false);
  servo(40, 0, 0, true);
  EXPECT_FALSE(feedback_[1].fault) << reason();
  EXPECT_EQ(sim_->status(11) & 4u, 0u);
}

// A servo thread that stores setpoints without pause: the bus thread often finds a store in
// progress, and must then send the previous setpoint, never an empty one (target 0, drive
// disabled) nor take it for a reset request.
class BusyServo {
 public:
  BusyServo(ModbusDriver& driver, double x, double y)
      : thread_([&driver, x, y, this] {
          const JointCommand c[2] = {{x, 0, true}, {y, 0, true}};
          while (!done_.load(std::memory_order_relaxed))
            driver.write(c, 2);
        }) {}
  ~BusyServo() {
    done_ = true;
    thread_.join();
  }
  BusyServo(const BusyServo&) = delete;
  BusyServo& operator=(const BusyServo&) = delete;

 private:
  std::atomic<bool> done_{false};
  std::thread thread_;
};

constexpr std::uint64_t kBusyUpdates = 100;

TEST_F(ModbusDriverTest, SetpointsStoredWithoutPauseReachTheDriveWhole) {
  start_sim();
  start_driver();
  servo(30, 1.234, -0.5, true);
  ASSERT_EQ(sim_->target(10), 1234) << reason();
  BusyServo busy(driver_, 1.234, -0.5);
  const std::uint64_t writes = sim_->target_writes(10);
  int wrong = 0;
  // A hundred updates (half a second, longer on a loaded machine).
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (sim_->target_writes(10) < writes + kBusyUpdates &&
         std::chrono::steady_clock::now() < until) {
    if (sim_->target(10) != 1234 || sim_->target(11) != -500 || (sim_->control(10) & 1u) == 0 ||
        (sim_->control(11) & 1u) == 0) {
      ++wrong;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  EXPECT_GE(sim_->target_writes(10), writes + kBusyUpdates) << "the bus kept updating";
  EXPECT_EQ(wrong, 0) << "the drives saw another target or lost their enable";
  EXPECT_EQ(reason(), "");
}

TEST_F(ModbusDriverTest, ALatchedFaultStaysLatchedWhileSetpointsKeepComing) {
  ASSERT_TRUE(run_until_drive_11_faults(0.1, 0.2));
  sim_->set_fault(11, false);  // the drive could be reset now, but nobody asked
  BusyServo busy(driver_, 0.1, 0.2);
  const std::uint64_t writes = sim_->target_writes(11);
  const std::uint64_t running = sim_->target_writes(10);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (sim_->target_writes(10) < running + kBusyUpdates &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GE(sim_->target_writes(10), running + kBusyUpdates) << "the other drive kept its updates";
  EXPECT_EQ(sim_->target_writes(11), writes) << "no setpoints while the fault is latched";
  EXPECT_EQ(sim_->control(11) & 3u, 0u) << "neither enabled nor reset";
  EXPECT_NE(reason().find("slave 11"), std::string::npos) << reason();
}

TEST_F(ModbusDriverTest, ExceptionRepliesAndSilenceFault) {
  start_sim();
  start_driver();
  servo(30, 0, 0, true);
  EXPECT_EQ(driver_.exchange_errors(), 0u);
  sim_->set_exception(true);
  EXPECT_TRUE(servo_until([&] { return feedback_[0].fault; }, 2000, 0, 0, true));
  const std::uint64_t exceptions = driver_.exchange_errors();
  EXPECT_GT(exceptions, 0u) << "exception replies count";
  EXPECT_NE(reason().find("Illegal data address"), std::string::npos) << reason();
  sim_->set_exception(false);
  servo(20, 0, 0, false);
  EXPECT_TRUE(servo_until([&] { return !faulted(0); }, 2000, 0, 0, true)) << reason();
  servo(20, 0, 0, true);
  EXPECT_FALSE(faulted(0)) << reason();
  sim_->set_silent(true);
  EXPECT_TRUE(servo_until([&] { return feedback_[0].fault; }, 3000, 0, 0, true));
  EXPECT_NE(reason().find("timeout"), std::string::npos) << reason();
  EXPECT_GT(driver_.exchange_errors(), exceptions) << "timeouts count";
}

TEST_F(ModbusDriverTest, RtuOverAPseudoTerminalPair) {
  DriveSimOptions options;
  options.rtu = true;
  options.first_slave = 10;
  options.lag_s = 0;
  options.rt_priority = kSimPriority;
  sim_ = std::make_unique<DriveSim>(options);
  if (const auto error = sim_->start(); !error.empty()) GTEST_SKIP() << error;
  loaded_ = load_machine(
      dir_, 1, kJointKeys,
      // Each way crosses two pseudo-terminals, whose bytes the kernel hands on from ordinary
      // worker threads: on a busy machine that takes longer than a serial line would.
      bus_section("TRANSPORT = rtu\nDEVICE = " + sim_->device() + "\nBAUD = 115200\nPARITY = N\n",
                  500));
  ASSERT_TRUE(loaded_.ok());
  ASSERT_EQ(driver_.configure(*loaded_.config, {0}), "");
  driver_.enable();
  for (int i = 0; i < 150; ++i) {
    driver_.read(feedback_, 1);
    JointCommand c{-2.5, 0, true};
    driver_.write(&c, 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  driver_.read(feedback_, 1);
  EXPECT_EQ(sim_->target(10), -2500);
  EXPECT_DOUBLE_EQ(feedback_[0].position, -2.5);
  EXPECT_FALSE(feedback_[0].fault || feedback_[0].stale) << reason();
}

}  // namespace
}  // namespace cncd::test
