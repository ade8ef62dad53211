// Step generation through the driver interface, recorded by the VCD backend in virtual time
// and in real time.
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/drivers/gpio_driver.hpp"
#include "test_util.hpp"

namespace cncd::test {
namespace {

using drivers::GpioDriver;
using drivers::JointCommand;
using drivers::JointFeedback;

constexpr std::int64_t kBaseNs = 10'000;  // 10 us: 100 base periods per servo period
constexpr std::int64_t kServoNs = 1'000'000;
constexpr double kScale = 100;  // steps/mm

std::string stepgen_keys(const std::string& extra = "") {
  return "DRIVER = gpio\nSCALE = 100\nSTEP_LINE = {j}0\nDIR_LINE = {j}1\nENABLE_LINE = {j}2\n"
         "STEPLEN = 20000\nSTEPSPACE = 15000\nDIRSETUP = 30000\nDIRHOLD = 25000\n" +
         extra;
}

std::string gpio_section(const TempDir& dir) {
  return "[GPIO]\nCHIP = vcd:" + (dir.path() / "steps.vcd").string() + "\n";
}

// One servo period in virtual time: the command, then the base periods until the next one.
void servo_period(GpioDriver& driver, const std::vector<double>& positions,
                  const std::vector<double>& previous, std::int64_t& now_ns) {
  std::vector<JointCommand> commands(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    commands[i].position = positions[i];
    commands[i].velocity = (positions[i] - previous[i]) / (static_cast<double>(kServoNs) * 1e-9);
    commands[i].enable = true;
  }
  driver.write(commands.data(), static_cast<int>(commands.size()));
  for (std::int64_t t = 0; t < kServoNs; t += kBaseNs) {
    driver.run_base_period(now_ns);
    now_ns += kBaseNs;
  }
}

// A smooth move (cosine velocity profile) from `from` to `to` over `seconds`.
double ramp(double from, double to, double t, double seconds) {
  const double u = std::clamp(t / seconds, 0.0, 1.0);
  return from + (to - from) * (1 - std::cos(u * M_PI)) / 2;
}

// A gpio step/dir driver on the first joints of a machine whose lines go to dir_/steps.vcd, in
// virtual time: each test advances now_ns_ itself.
class GpioStepgenTest : public ::testing::Test {
 protected:
  void start(int joints, const std::string& extra_keys = "") {
    loaded_ = load_machine(dir_, joints, stepgen_keys(extra_keys), gpio_section(dir_), kBaseNs);
    ASSERT_TRUE(loaded_.ok());
    driver_.use_manual_clock(true);
    std::vector<int> indexes(static_cast<std::size_t>(joints));
    std::iota(indexes.begin(), indexes.end(), 0);
    ASSERT_EQ(driver_.configure(*loaded_.config, indexes), "");
    driver_.enable();
  }

  TempDir dir_;
  config::LoadResult loaded_;
  GpioDriver driver_;
  std::int64_t now_ns_ = 0;
};

TEST_F(GpioStepgenTest, PulseCountsAndTimingInVirtualTime) {
  ASSERT_NO_FATAL_FAILURE(start(2));
  std::vector<double> previous{0, 0};
  // Out to X 5 / Y -3, back through zero to X -2.37 / Y 1.5, then hold still.
  const struct {
    double x, y, seconds;
  } moves[] = {{5, -3, 0.4}, {-2.37, 1.5, 0.5}, {-2.37, 1.5, 0.05}};
  for (const auto& m : moves) {
    const std::vector<double> start = previous;
    for (double t = 0; t < m.seconds; t += 1e-3) {
      const std::vector<double> p{ramp(start[0], m.x, t + 1e-3, m.seconds),
                                  ramp(start[1], m.y, t + 1e-3, m.seconds)};
      servo_period(driver_, p, previous, now_ns_);
      previous = p;
    }
  }
  JointFeedback fb[2];
  driver_.read(fb, 2);
  driver_.disable();
  EXPECT_EQ(driver_.step_count(0), -237);
  EXPECT_EQ(driver_.step_count(1), 150);
  EXPECT_DOUBLE_EQ(fb[0].position, -2.37);
  EXPECT_DOUBLE_EQ(fb[1].position, 1.5);
  EXPECT_FALSE(fb[0].stale);

  const auto changes = read_vcd(dir_.path() / "steps.vcd");
  for (int j = 0; j < 2; ++j) {
    const StepStats s = step_stats(changes, j);
    SCOPED_TRACE("joint " + std::to_string(j));
    EXPECT_EQ(s.net_steps, driver_.step_count(j));
    EXPECT_GE(s.direction_changes, 1);
    EXPECT_GE(s.min_high_ns, 20'000);
    EXPECT_GE(s.min_low_ns, 15'000);
    EXPECT_GE(s.min_dir_setup_ns, 30'000);
    EXPECT_GE(s.min_dir_hold_ns, 25'000);
  }
  // Every step made its way to the file: 500 + 737 steps of X, 300 + 450 of Y.
  EXPECT_EQ(step_stats(changes, 0).rising_edges, 1237);
  EXPECT_EQ(step_stats(changes, 1).rising_edges, 750);
}

// Staleness counts servo periods that ran without a base period, not wall time: after a stall
// of the whole machine the base thread catches up, and only a base thread that stays silent
// while the servo thread runs is a fault.
TEST_F(GpioStepgenTest, FeedbackIsStaleAfterTwentyServoPeriodsWithoutABasePeriod) {
  ASSERT_NO_FATAL_FAILURE(start(1));
  const std::vector<double> rest{0};
  JointFeedback fb;
  servo_period(driver_, rest, rest, now_ns_);
  std::this_thread::sleep_for(std::chrono::milliseconds(60));  // 60 servo periods of wall time
  driver_.read(&fb, 1);
  EXPECT_FALSE(fb.stale);
  for (int i = 1; i < 20; ++i) {
    driver_.read(&fb, 1);
    ASSERT_FALSE(fb.stale) << "after " << i << " silent servo periods";
  }
  driver_.read(&fb, 1);
  EXPECT_TRUE(fb.stale) << "after 20 silent servo periods";
  driver_.read(&fb, 1);
  EXPECT_TRUE(fb.stale);
  servo_period(driver_, rest, rest, now_ns_);
  driver_.read(&fb, 1);
  EXPECT_FALSE(fb.stale);
}

TEST_F(GpioStepgenTest, EnableLineFollowsTheCommandAndNothingStepsWhileDisabled) {
  ASSERT_NO_FATAL_FAILURE(start(1));
  JointCommand off{10, 0, false};
  for (int i = 0; i < 20; ++i) {
    driver_.write(&off, 1);
    for (int k = 0; k < 100; ++k)
      driver_.run_base_period(now_ns_ += kBaseNs);
  }
  EXPECT_EQ(driver_.step_count(0), 1000) << "the first command places the motor without stepping";
  JointCommand on{10.5, 0, true};
  for (int i = 0; i < 50; ++i) {
    driver_.write(&on, 1);
    for (int k = 0; k < 100; ++k)
      driver_.run_base_period(now_ns_ += kBaseNs);
  }
  driver_.disable();
  EXPECT_EQ(driver_.step_count(0), 1050);
  const auto changes = read_vcd(dir_.path() / "steps.vcd");
  int enable_edges = 0;
  for (const auto& c : changes)
    if (c.signal == "j0_enable" && c.level == 1) ++enable_edges;
  EXPECT_EQ(enable_edges, 1);
  EXPECT_EQ(step_stats(changes, 0).rising_edges, 50);
}

TEST_F(GpioStepgenTest, StepgenLimitsBoundTheStepRate) {
  ASSERT_NO_FATAL_FAILURE(start(1, "STEPGEN_MAXVEL = 10\nSTEPGEN_MAXACCEL = 200\n"));
  JointCommand start{0, 0, true};
  driver_.write(&start, 1);
  driver_.run_base_period(now_ns_);
  // A 20 mm jump: at 10 mm/s and 200 mm/s^2 it takes 2.05 s, never faster.
  JointCommand jump{20, 0, true};
  driver_.write(&jump, 1);
  std::int64_t after_1s = 0;
  for (int k = 1; k <= 300'000; ++k) {
    driver_.run_base_period(now_ns_ += kBaseNs);
    if (k == 100'000) after_1s = driver_.step_count(0);
  }
  driver_.disable();
  EXPECT_LE(after_1s, 1000);  // at most 10 mm/s * 1 s
  EXPECT_GE(after_1s, 900);   // after 0.05 s of acceleration it runs at full speed
  EXPECT_EQ(driver_.step_count(0), 2000);
}

TEST(GpioStepgen, RealTimeBaseThreadReachesTheCommand) {
  TempDir dir;
  const auto loaded = load_machine(dir, 1, stepgen_keys(), gpio_section(dir), 20'000);
  ASSERT_TRUE(loaded.ok());
  GpioDriver driver;
  driver.pace_recording_in_real_time(true);  // a base period every 20 us, as for pins
  ASSERT_EQ(driver.configure(*loaded.config, {0}), "");
  driver.enable();
  // The step generator takes the first command it sees as where the motor stands; hold still at
  // 0 until the base thread has certainly seen it, however loaded the machine is.
  const JointCommand rest{0, 0, true};
  while (driver.base_stats().periods < 100) {
    driver.write(&rest, 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  auto next = std::chrono::steady_clock::now();
  double previous = 0;
  for (int i = 0; i <= 400; ++i) {
    const double p = ramp(0, 3, i * 1e-3, 0.3);
    JointCommand c{p, (p - previous) / 1e-3, true};
    previous = p;
    driver.write(&c, 1);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  // On a loaded machine the base thread may trail the command by a few periods: hold the end
  // command until it arrives (or give up after 2 s and let the checks below tell).
  const JointCommand end{previous, 0, true};
  for (int i = 0; i < 2000 && driver.step_count(0) != 300; ++i) {
    driver.write(&end, 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  JointFeedback fb;
  driver.read(&fb, 1);
  const auto stats = driver.base_stats();
  driver.disable();
  EXPECT_FALSE(fb.stale);
  EXPECT_EQ(driver.step_count(0), 300);
  EXPECT_GT(stats.periods, 10'000u);
  const StepStats s = step_stats(read_vcd(dir.path() / "steps.vcd"), 0);
  EXPECT_EQ(s.net_steps, 300);
  EXPECT_EQ(s.rising_edges, 300);
}

}  // namespace
}  // namespace cncd::test
