// The servo thread's event records put in words: one case per code, each the text the status
// and the event log show.
#include "cncd/motion/rt_event.hpp"

#include <cstring>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace cncd::motion {
namespace {

using Code = RtEvent::Code;

RtEvent event(Code code, int joint = -1) {
  RtEvent e;
  e.code = code;
  e.joint = static_cast<std::int8_t>(joint);
  return e;
}

RtEvent with_words(Code code, int joint, const char* words) {
  RtEvent e = event(code, joint);
  e.words = words;
  return e;
}

RtEvent with_text(Code code, int joint, const char* text) {
  RtEvent e = event(code, joint);
  drivers::copy_text(e.text, sizeof e.text, text);
  return e;
}

RtEvent following(double error, double limit, std::uint64_t oldest, std::uint64_t newest) {
  return {.code = Code::following_error,
          .joint = 0,
          .error = error,
          .limit = limit,
          .oldest_ago = oldest,
          .newest_ago = newest};
}

TEST(FormatEvent, NoneIsEmpty) {
  EXPECT_EQ(format_event(RtEvent{}), "");
}

TEST(FormatEvent, Estop) {
  EXPECT_EQ(format_event(event(Code::estop)), "estop");
}

TEST(FormatEvent, EstopInput) {
  EXPECT_EQ(format_event(event(Code::estop_input)), "estop input asserted");
}

TEST(FormatEvent, HomeIgnored) {
  EXPECT_EQ(format_event(event(Code::home_ignored_not_on)), "home ignored: the machine is not on");
  EXPECT_EQ(format_event(event(Code::home_ignored_moving)), "home ignored: the machine is moving");
}

TEST(FormatEvent, HomingAborted) {
  EXPECT_EQ(format_event(event(Code::homing_aborted)), "homing aborted");
}

TEST(FormatEvent, HomingInProgress) {
  EXPECT_EQ(format_event(event(Code::homing_in_progress)), "homing is already in progress");
}

TEST(FormatEvent, HomingFailed) {
  EXPECT_EQ(format_event(with_words(Code::homing_failed, 2,
                                    "home switch not found within twice the joint's travel")),
            "joint 2: home switch not found within twice the joint's travel");
}

TEST(FormatEvent, HomingNeedsSwitchNamesTheDriver) {
  EXPECT_EQ(format_event(with_text(Code::homing_needs_switch, 1, "modbus")),
            "joint 1: switch homing needs a home switch input, which driver 'modbus' lacks");
}

TEST(FormatEvent, HomingTextIsCutAt120Characters) {
  const std::string name(150, 'd');
  const std::string text = format_event(with_text(Code::homing_needs_switch, 1, name.c_str()));
  EXPECT_EQ(text.size(), 119u);
  EXPECT_EQ(text.rfind("joint 1: switch homing needs a home switch input, which driver 'dd", 0),
            0u);
}

TEST(FormatEvent, JogIgnored) {
  EXPECT_EQ(format_event(with_words(Code::jog_ignored, -1, "the machine has no such axis")),
            "jog ignored: the machine has no such axis");
}

TEST(FormatEvent, FeedbackNotANumber) {
  EXPECT_EQ(format_event(event(Code::feedback_not_a_number, 2)),
            "joint 2: feedback position is not a number");
}

TEST(FormatEvent, DriveFaultWithAndWithoutTheDriversWords) {
  EXPECT_EQ(format_event(event(Code::drive_fault, 1)), "joint 1: drive fault");
  EXPECT_EQ(format_event(with_text(Code::drive_fault, 2, "fault injected on simulated drive 2")),
            "joint 2: drive fault: fault injected on simulated drive 2");
}

TEST(FormatEvent, FeedbackStaleWithAndWithoutTheDriversWords) {
  EXPECT_EQ(format_event(event(Code::feedback_stale, 0)), "joint 0: feedback is stale");
  EXPECT_EQ(format_event(with_text(Code::feedback_stale, 1, "bus silent for 40 ms")),
            "joint 1: feedback is stale: bus silent for 40 ms");
}

TEST(FormatEvent, DriversLongestWordsFit) {
  const std::string words(drivers::kFaultReasonSize - 1, 'w');
  EXPECT_EQ(format_event(with_text(Code::feedback_stale, 15, words.c_str())),
            "joint 15: feedback is stale: " + words);
}

TEST(FormatEvent, LimitSwitches) {
  EXPECT_EQ(format_event(event(Code::min_limit_switch, 0)),
            "joint 0: minimum limit switch tripped");
  EXPECT_EQ(format_event(event(Code::max_limit_switch, 1)),
            "joint 1: maximum limit switch tripped");
}

TEST(FormatEvent, FollowingError) {
  EXPECT_EQ(format_event(following(0.6, 0.5, 0, 0)),
            "joint 0: following error 0.6000 exceeds 0.5000");
  EXPECT_EQ(format_event(following(0.6, 0.5, 3, 3)),
            "joint 0: following error 0.6000 exceeds 0.5000 (against the command of 3 periods "
            "ago)");
  EXPECT_EQ(format_event(following(0.6, 0.5, 5, 2)),
            "joint 0: following error 0.6000 exceeds 0.5000 (against the commands of 5 to 2 "
            "periods ago)");
  EXPECT_EQ(format_event(following(1e300, 1e300, 0, 0)),
            "joint 0: following error 1000000000.0000 exceeds 1000000000.0000");
}

TEST(FormatEvent, SetPointNotFinite) {
  EXPECT_EQ(format_event(event(Code::set_point_not_finite, 1)), "non-finite set-point on joint 1");
}

TEST(FormatEvent, JointsApart) {
  RtEvent e = event(Code::joints_apart, 3);
  e.axis = 1;
  EXPECT_EQ(format_event(e),
            "joint 3 stands apart from axis Y: home the joints of an axis together, to the same "
            "HOME");
}

TEST(FormatEvent, OffPath) {
  EXPECT_EQ(format_event(event(Code::off_path)),
            "a queued move does not start where the machine stands");
}

TEST(FormatEvent, IntoABufferCutsAndCountsTheWholeText) {
  char small[8];
  const std::size_t n = format_event(event(Code::homing_aborted), small, sizeof small);
  EXPECT_EQ(n, std::strlen("homing aborted"));
  EXPECT_STREQ(small, "homing ");
}

TEST(CopyText, CutsToFit) {
  char out[4];
  drivers::copy_text(out, sizeof out, "abcdef");
  EXPECT_STREQ(out, "abc");
  drivers::copy_text(out, sizeof out, "");
  EXPECT_STREQ(out, "");
}

// The event log and /metrics name a fault by its code: one name per code, as the enum spells it.
TEST(EventCodeName, EachCodeHasItsOwnName) {
  EXPECT_STREQ(event_code_name(Code::none), "");
  EXPECT_STREQ(event_code_name(Code::estop), "estop");
  EXPECT_STREQ(event_code_name(Code::following_error), "following_error");
  EXPECT_STREQ(event_code_name(Code::drive_fault), "drive_fault");
  EXPECT_STREQ(event_code_name(Code::sync_not_at_rest), "sync_not_at_rest");
  std::set<std::string> names;
  const auto last = static_cast<int>(Code::sync_not_at_rest);
  for (int c = 1; c <= last; ++c) {
    const std::string name = event_code_name(static_cast<Code>(c));
    EXPECT_FALSE(name.empty()) << c;
    EXPECT_TRUE(names.insert(name).second) << name << " twice";
  }
  EXPECT_STREQ(event_code_name(static_cast<Code>(last + 1)), "");
}

}  // namespace
}  // namespace cncd::motion
