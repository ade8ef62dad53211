// wait.done on the real daemon: the operator ends an M66 wait (it goes on as on its timeout,
// #5399 = -1) or a spindle at-speed wait (the feed goes on while the spindle turns), and an
// answer for a wait that is not under way is refused and changes nothing.
#include <fstream>
#include <regex>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class WaitDone : public MachineTest {
 protected:
  // Restarts cncd with the spindle speeding up at `rpm_per_s` and waiting up to a minute.
  void restart_with_slow_spindle(int rpm_per_s) {
    daemon_.stop();
    std::string text = slurp(ini_);
    text = std::regex_replace(text, std::regex("\nACCELERATION = 6000\n"),
                              "\nACCELERATION = " + std::to_string(rpm_per_s) + "\n");
    text = std::regex_replace(text, std::regex("\nAT_SPEED_TIMEOUT = 10\n"),
                              "\nAT_SPEED_TIMEOUT = 60\n");
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  json wait_for(const std::string& kind) {
    return wait_until([&](const json& s) {
      return (s["wait"].is_object() && s["wait"]["kind"] == kind) || s["exec"] == "idle";
    });
  }
  json idle() {
    return wait_until([](const json& s) { return s["exec"] == "idle"; });
  }
};

TEST_F(WaitDone, EndsAnInputWaitAsItsTimeoutWould) {
  ready_machine();
  // Input 2 is never set: without an answer the program waits ten minutes.
  start_program("m66.ngc",
                "M66 P2 L3 Q600\n"
                "o1 if [#5399 EQ -1]\n"
                "  G0 X3\n"
                "o1 else\n"
                "  G0 X9\n"
                "o1 endif\n"
                "M2\n");
  const json waiting = wait_for("input");
  ASSERT_EQ(waiting["wait"]["kind"], "input") << waiting.dump();
  // The wrong kind changes nothing.
  EXPECT_EQ(error_code(call("wait.done", {{"kind", "spindle_at_speed"}})), 1001);
  EXPECT_EQ(error_code(call("wait.done", {{"kind", "coffee"}})), -32602);
  EXPECT_EQ(status()["wait"]["kind"], "input");
  result_of(call("wait.done", {{"kind", "input"}}));
  const json s = idle();
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 3.0);
  const json events = result_of(call("errors.list"));
  EXPECT_NE(events.dump().find("the wait for digital input 2 was ended"), std::string::npos)
      << events.dump();
  // Nothing is waiting now.
  EXPECT_EQ(error_code(call("wait.done", {{"kind", "input"}})), 1001);
}

TEST_F(WaitDone, LetsTheFeedGoOnWhileTheSpindleTurnsBelowSpeed) {
  // 3000 rpm at 100 rpm/s takes 30 s.
  ASSERT_NO_FATAL_FAILURE(restart_with_slow_spindle(100));
  ready_machine();
  start_program("spin.ngc", "G0 X0 Y0 Z5\nM3 S3000\nG1 Z4 F600\nM2\n");
  const json waiting = wait_for("spindle_at_speed");
  ASSERT_EQ(waiting["wait"]["kind"], "spindle_at_speed") << waiting.dump();
  wait_until([](const json& s) { return s["spindle"]["actual_rpm"].get<double>() > 100; });
  result_of(call("wait.done", {{"kind", "spindle_at_speed"}}));
  const json s = idle();
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["z"], 4.0);
  EXPECT_LT(s["spindle"]["actual_rpm"].get<double>(), 2850.0) << "it did not wait for speed";
}

}  // namespace
}  // namespace cncd::test
