// The sim lathe (config/examples/sim_lathe.ini): an XZ machine that starts in G8 (radii), and
// runs examples/lathe_turning.ngc (G7 diameters, G96 turning, G33 threading) and a G76 thread
// to done.
#include <algorithm>
#include <string>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class LatheTest : public MachineTest {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), "sim_lathe");
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  bool has_code(const json& s, const std::string& code) {
    for (const auto& c : s["gcodes"])
      if (c == code) return true;
    return false;
  }
};

TEST_F(LatheTest, StartsInTheXzPlaneWithRadiiAndRunsTheTurningExample) {
  ready_machine();
  json s = status();
  EXPECT_TRUE(has_code(s, "G8")) << s["gcodes"].dump();
  EXPECT_EQ(s["diameter_mode"], false);
  EXPECT_EQ(s["position"]["commanded"].size(), 2u) << s["position"].dump();

  const auto program = dir_.write(
      "lathe_turning.ngc", slurp(std::string(CNCD_SOURCE_DIR) + "/examples/lathe_turning.ngc"));
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  bool threaded = false;
  bool turned_at_css = false;
  s = wait_until([&](const json& st) {
    // The thread passes run in step with the spindle; the turning passes under G96.
    if (!st["sync"].is_null()) threaded = true;
    // The operator puts in the tool each M6 asks for.
    if (st["wait"].is_object() && st["wait"]["kind"] == "tool_change")
      result_of(call("tool.change_done", {{"tool", st["wait"]["tool"]}}));
    if (!st["spindle"]["css"].is_null() && st["spindle"]["actual_rpm"].get<double>() > 0)
      turned_at_css = true;
    return st["exec"] == "idle";
  });
  EXPECT_EQ(s["program"]["result"], "done") << s["program"].dump();
  EXPECT_TRUE(threaded);
  EXPECT_TRUE(turned_at_css);
  // G0 X40 Z10 under G7 with T2 (X -1.5, Z -3): radius 20 - 1.5, Z 10 - 3; the DRO shows the
  // diameter the program wrote.
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 18.5, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 7.0, 1e-9);
  EXPECT_EQ(s["diameter_mode"], true);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 40.0, 1e-9);
}

// The M12x1.75 G76 of tests/golden/lathe_g76_m12 (its passes on the helix are checked in
// g76_plan_test.cpp): 14 passes, each in step with the spindle, to done.
TEST_F(LatheTest, RunsAG76ThreadToDone) {
  ready_machine();
  const auto program = dir_.write(
      "m12.ngc", slurp(std::string(CNCD_SOURCE_DIR) + "/tests/golden/lathe_g76_m12/program.ngc"));
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  int passes = 0;
  bool synced = false;
  double deepest = 1e9;
  const json s = wait_until([&](const json& st) {
    const bool now = !st["sync"].is_null() && st["sync"]["mode"] == "thread";
    if (now && !synced) ++passes;
    synced = now;
    if (now) deepest = std::min(deepest, st["position"]["commanded"]["x"].get<double>());
    return st["exec"] == "idle";
  });
  EXPECT_EQ(s["program"]["result"], "done") << s["program"].dump();
  // Status is sampled: a pass lasts a second, the moves between them a fraction of one.
  EXPECT_GE(passes, 7);
  EXPECT_LE(passes, 14);
  EXPECT_NEAR(deepest, 7 - 1 - 1.07, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 20, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), -20, 1e-9);
}

}  // namespace
}  // namespace cncd::test
