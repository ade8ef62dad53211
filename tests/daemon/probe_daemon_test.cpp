// G38.x through the real daemon on the example sim machine, whose simulated block has its top
// at Z -3.2: the probe result reaches #5061-#5070 and the lines after the probe, status shows
// it, and the probing errors end the program naming the line.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class ProbeDaemon : public MachineTest {
 protected:
  // Runs `body` from X10 Y20 Z`from` and waits for the end.
  nlohmann::json run(const std::string& body, double from = 0) {
    start_program("probe.ngc",
                  "G21 G90 G49\nG0 X10 Y20 Z" + std::to_string(from) + "\n" + body + "M2\n");
    return wait_until([](const nlohmann::json& s) {
      return s["exec"] == "idle" && s["program"]["result"] != "";
    });
  }
  static double z(const nlohmann::json& s) { return s["position"]["commanded"]["z"].get<double>(); }
  static double x(const nlohmann::json& s) { return s["position"]["commanded"]["x"].get<double>(); }
};

TEST_F(ProbeDaemon, G38_2FindsTheSurfaceAndTheProgramReadsOnWithTheResult) {
  ready_machine();
  // #5063 + 10 and 10 + #5070 carry the result into positions the status shows.
  const auto s = run("G38.2 Z-10 F50\nG0 Z[#5063 + 10]\nG0 X[10 + #5070]\n");
  ASSERT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_NEAR(z(s), -3.2 + 10, 0.002);
  EXPECT_NEAR(x(s), 11, 1e-9);
  EXPECT_EQ(s["probe"]["last_result"], 1);
  EXPECT_NEAR(s["probe"]["last_position"]["z"].get<double>(), -3.2, 0.002);
  EXPECT_FALSE(s["probe"]["tripped"].get<bool>());  // back above the block
  EXPECT_FALSE(s["probe"]["probing"].get<bool>());
}

TEST_F(ProbeDaemon, G38_3AboveTheSurfaceEndsWithoutContactAndWithoutError) {
  ready_machine();
  const auto s = run("G38.3 Z-1 F50\nG0 X[10 + #5070]\n");
  ASSERT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_NEAR(x(s), 10, 1e-9);  // #5070 = 0
  EXPECT_NEAR(z(s), -1, 1e-9);
  EXPECT_EQ(s["probe"]["last_result"], 0);
}

TEST_F(ProbeDaemon, G38_2WithoutContactIsAnErrorAtItsLine) {
  ready_machine();
  const auto s = run("G38.2 Z-1 F50\nG0 X50\n");
  EXPECT_EQ(s["program"]["result"], "error");
  EXPECT_NE(s["program"]["error"].get<std::string>().find(
                "probe.ngc:3: G38.2 probe move finished without tripping the probe"),
            std::string::npos)
      << s.dump();
  EXPECT_NEAR(x(s), 10, 1e-9);  // nothing after it ran
  EXPECT_EQ(s["state"], "on");
}

TEST_F(ProbeDaemon, G38_4FromInsideBacksOffToWhereContactIsLost) {
  ready_machine();
  const auto s = run("G38.4 Z0 F50\nG0 Z[#5063 + 5]\n", -5);
  ASSERT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_NEAR(z(s), -3.2 + 5, 0.002);
  EXPECT_EQ(s["probe"]["last_result"], 1);
}

TEST_F(ProbeDaemon, AProbeTouchingAtTheStartIsRefused) {
  ready_machine();
  const auto s = run("G38.2 Z-10 F50\n", -5);
  EXPECT_EQ(s["program"]["result"], "error");
  EXPECT_NE(s["program"]["error"].get<std::string>().find(
                "probe is already tripped when starting a G38.2 or G38.3 move"),
            std::string::npos)
      << s.dump();
}

}  // namespace
}  // namespace cncd::test
