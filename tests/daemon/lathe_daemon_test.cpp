// The sim lathe (config/examples/sim_lathe.ini): an XZ machine that starts in G8 (radii), and
// runs examples/lathe_turning.ngc (G7 diameters, G96 turning, G33 threading) to done.
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

}  // namespace
}  // namespace cncd::test
