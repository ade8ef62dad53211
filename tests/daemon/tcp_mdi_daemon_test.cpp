// MDI under TCP on the sim trunnion (config/examples/sim_xyzac_trt.ini), on the real daemon:
// an MDI command keeps the TCP state the last one left, and starts from where the tool tip
// stands in the part's frame, not from the joints. With the table tilted to A -30, `G1 Z15`
// from the tip at Z 20 moves the tip 5 mm down the part's Z: the joints along the tilted
// direction (Y by 2.5, Z by 4.33), X not at all. Taken from the joints, the start would be
// elsewhere and the move would carry the tool sideways.
#include <cmath>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class TrunnionMdiTest : public MachineTest {
 protected:
  std::string example() const override { return "sim_xyzac_trt"; }
  nlohmann::json idle_with(const char* axis, double value) {
    return wait_until([axis, value](const nlohmann::json& s) {
      return s["motion"] == "idle" &&
             std::abs(s["position"]["commanded"][axis].get<double>() - value) < 1e-9;
    });
  }
};

TEST_F(TrunnionMdiTest, AnMdiCommandUnderTcpStartsFromTheToolTip) {
  ready_machine();
  mdi("G0 X10 Y5 Z20 A0 C0");
  idle_with("z", 20);
  mdi("M428");
  mdi("G0 A-30");
  const nlohmann::json tilted = idle_with("a", -30);
  mdi("G1 Z15 F600");
  const nlohmann::json down = wait_until([&tilted](const nlohmann::json& s) {
    return s["motion"] == "idle" &&
           s["position"]["commanded"]["z"] != tilted["position"]["commanded"]["z"];
  });
  const auto& before = tilted["position"]["commanded"];
  const auto& after = down["position"]["commanded"];
  EXPECT_NEAR(after["x"].get<double>() - before["x"].get<double>(), 0, 1e-9) << after.dump();
  EXPECT_NEAR(std::abs(after["y"].get<double>() - before["y"].get<double>()), 2.5, 1e-6)
      << before.dump() << after.dump();
  EXPECT_NEAR(std::abs(after["z"].get<double>() - before["z"].get<double>()), 5 * std::sqrt(0.75),
              1e-6);
  EXPECT_NEAR(after["a"].get<double>(), -30, 1e-9);
  mdi("G0 A0");
  mdi("M429");
}

}  // namespace
}  // namespace cncd::test
