// The feedback checks alone: commands recorded and feedback judged by hand, without a servo
// loop or a driver behind them.
#include "cncd/motion/feedback_checks.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::motion {
namespace {

using Feedbacks = FeedbackChecks::JointFeedbacks;

// Every joint of the small mill commanded to `position` at `velocity`, drives enabled.
void record(FeedbackChecks& checks, std::uint64_t cycle, double position, double velocity = 0,
            bool enable = true) {
  drivers::JointCommand commands[3];
  for (auto& c : commands) {
    c.position = position;
    c.velocity = velocity;
    c.enable = enable;
    c.cycle = cycle;
  }
  checks.record(cycle, commands);
}

Feedbacks at(double position) {
  Feedbacks fb{};
  for (int j = 0; j < 3; ++j)
    fb[static_cast<std::size_t>(j)].position = position;
  return fb;
}

// The first joint that failed and why, in words.
struct Fault {
  int joint = -1;
  char text[kEventTextSize] = {};
};

struct Checked {
  bool ok;
  Fault fault;
};

Checked check(const FeedbackChecks& checks, const Feedbacks& fb, std::uint64_t cycle,
              std::uint32_t limits_ignored = 0) {
  Checked c{};
  RtEvent event;
  c.ok = checks.check(fb, cycle, limits_ignored, event);
  c.fault.joint = event.joint;
  if (!c.ok) format_event(event, c.fault.text, sizeof c.fault.text);
  return c;
}

// A failed check that names `joint` and says `text`.
void expect_fault(const Checked& c, int joint, const char* text) {
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.fault.joint, joint);
  EXPECT_STREQ(c.fault.text, text);
}

class FeedbackChecksTest : public ::testing::Test {
 protected:
  config::MachineConfig config_ = test::small_mill();  // FERROR 1, MIN_FERROR 0.5
  FeedbackChecks checks_{config_, 3, {}, CommandHistory::kMinDepth};
};

TEST_F(FeedbackChecksTest, FeedbackOnItsCommandPasses) {
  record(checks_, 1, 10);
  const Checked c = check(checks_, at(10.3), 2);
  EXPECT_TRUE(c.ok) << c.fault.text;
  EXPECT_EQ(c.fault.joint, -1);
}

TEST_F(FeedbackChecksTest, PositionThatIsNotANumberFails) {
  record(checks_, 1, 0);
  Feedbacks fb = at(0);
  fb[2].position = std::nan("");
  expect_fault(check(checks_, fb, 2), 2, "joint 2: feedback position is not a number");
}

// A flag of one joint's feedback that fails the check, with limit switches of
// `limits_ignored` (a bit per joint) ignored, and what the fault says.
struct BadFlag {
  bool drivers::JointFeedback::*flag;
  int joint;
  std::uint32_t limits_ignored;
  const char* text;
};

TEST_F(FeedbackChecksTest, DriveFaultStaleFeedbackAndLimitSwitchesFail) {
  record(checks_, 1, 0);
  using drivers::JointFeedback;
  for (const BadFlag& bad : {
           BadFlag{&JointFeedback::fault, 1, 0, "joint 1: drive fault"},
           BadFlag{&JointFeedback::stale, 0, 0, "joint 0: feedback is stale"},
           BadFlag{&JointFeedback::max_limit, 1, 0, "joint 1: maximum limit switch tripped"},
           BadFlag{&JointFeedback::min_limit, 0, 1u << 1, "joint 0: minimum limit switch tripped"},
       }) {
    Feedbacks fb = at(0);
    fb[static_cast<std::size_t>(bad.joint)].*bad.flag = true;
    expect_fault(check(checks_, fb, 2, bad.limits_ignored), bad.joint, bad.text);
  }
}

TEST_F(FeedbackChecksTest, IgnoredLimitSwitchPasses) {
  record(checks_, 1, 0);
  Feedbacks fb = at(0);
  fb[1].max_limit = true;
  EXPECT_TRUE(check(checks_, fb, 2, 1u << 1).ok);
}

TEST_F(FeedbackChecksTest, FollowingErrorLimitGrowsWithSpeed) {
  // At rest the limit is MIN_FERROR (0.5).
  record(checks_, 1, 0);
  expect_fault(check(checks_, at(0.6), 2), 0, "joint 0: following error 0.6000 exceeds 0.5000");
  // At 180 mm/s, 90 % of X's MAX_VELOCITY, FERROR (1) scales to 0.9 on X.
  record(checks_, 2, 0, 180);
  EXPECT_TRUE(check(checks_, at(0.6), 3).ok);
  expect_fault(check(checks_, at(-0.95), 3), 0, "joint 0: following error 0.9500 exceeds 0.9000");
}

TEST_F(FeedbackChecksTest, LateFeedbackIsJudgedAgainstTheCommandItAnswers) {
  for (std::uint64_t cycle = 1; cycle <= 10; ++cycle)
    record(checks_, cycle, static_cast<double>(cycle));
  // Measured while the drive had command 4: 6 behind the latest, on the one it answers.
  Feedbacks fb = at(4);
  for (auto& joint : fb)
    joint.command_cycle = 4;
  EXPECT_TRUE(check(checks_, fb, 11).ok);
  fb = at(2);
  for (auto& joint : fb)
    joint.command_cycle = 4;
  expect_fault(check(checks_, fb, 11), 0,
               "joint 0: following error 2.0000 exceeds 0.5000 (against the command of 6 periods "
               "ago)");
  // Between two commands it answers, anywhere counts.
  fb = at(5.5);
  for (auto& joint : fb) {
    joint.command_cycle = 8;
    joint.previous_cycle = 3;
  }
  EXPECT_TRUE(check(checks_, fb, 11).ok);
  // Without a cycle named, the latest command.
  EXPECT_FALSE(check(checks_, at(4), 11).ok);
  EXPECT_TRUE(check(checks_, at(10), 11).ok);
}

TEST_F(FeedbackChecksTest, CommandsSentWithTheDrivesOffAreNotFollowed) {
  record(checks_, 1, 0, 0, false);
  EXPECT_TRUE(check(checks_, at(100), 2).ok);
}

// A driver that only has words for its fault (the checks never move it).
class WordyDriver final : public test::FakeDriver {
 public:
  WordyDriver() : FakeDriver("wordy") {}
  bool fault_reason(char* out, std::size_t size) const noexcept override {
    std::snprintf(out, size, "%s", "bus silent for 40 ms");
    return true;
  }
};

TEST(FeedbackChecks, DriveFaultCarriesTheDriversOwnWords) {
  const auto config = test::small_mill();
  WordyDriver driver;
  FeedbackChecks::JointDrivers joint_driver{};
  joint_driver[1] = &driver;
  FeedbackChecks checks(config, 3, joint_driver, CommandHistory::kMinDepth);
  record(checks, 1, 0);
  Feedbacks fb = at(0);
  fb[1].stale = true;
  const Checked c = check(checks, fb, 2);
  EXPECT_FALSE(c.ok);
  EXPECT_STREQ(c.fault.text, "joint 1: feedback is stale: bus silent for 40 ms");
}

}  // namespace
}  // namespace cncd::motion
