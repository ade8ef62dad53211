// sim.set on the real daemon: it sets the sim inputs the INI names, as a wire would, and
// refuses (-32602, naming the signal) a name the INI does not give, an output, and a value the
// signal cannot take; without [PANEL] status.get's panel is null.
#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class SimSet : public MachineTest {
 protected:
  json sim_set(const std::string& signal, const json& value) {
    return call("sim.set", {{"signal", signal}, {"value", value}});
  }
  void expect_refused(const std::string& signal, const json& value, const std::string& part) {
    const json answer = sim_set(signal, value);
    ASSERT_EQ(error_code(answer), -32602) << answer.dump();
    const std::string message = answer["error"]["message"];
    EXPECT_NE(message.find("\"" + signal + "\""), std::string::npos) << message;
    EXPECT_NE(message.find(part), std::string::npos) << message;
  }
};

TEST_F(SimSet, SetsADigitalInputTheIniNames) {
  // sim_mm.ini: DIGITAL_INPUT_0 = sim:door_closed.
  EXPECT_EQ(status()["io"]["dins"][0], false);
  EXPECT_EQ(result_of(sim_set("door_closed", 1)), (json{{"ok", true}}));
  wait_until([](const json& s) { return s["io"]["dins"][0] == true; });
  result_of(sim_set("door_closed", 0));
  wait_until([](const json& s) { return s["io"]["dins"][0] == false; });
}

TEST_F(SimSet, RefusesWhatTheIniDoesNotNameOutputsAndBadValues) {
  expect_refused("no_such_signal", 1, "names no sim signal");
  expect_refused("flood", 1, "is an output");
  expect_refused("door_closed", 2, "must be 0 or 1");
  expect_refused("door_closed", 0.5, "must be 0 or 1");
  EXPECT_EQ(error_code(sim_set("door_closed", true)), -32602);
  const json missing = call("sim.set", {{"signal", "door_closed"}});
  EXPECT_EQ(error_code(missing), -32602);
  EXPECT_EQ(status()["io"]["dins"][0], false);
}

TEST_F(SimSet, StatusHasNoPanelWithoutAPanelSection) {
  const json s = status();
  ASSERT_TRUE(s.contains("panel"));
  EXPECT_TRUE(s["panel"].is_null());
}

}  // namespace
}  // namespace cncd::test
