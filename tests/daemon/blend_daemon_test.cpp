// Blending in the real daemon: a G64 program runs through its corners, comes to rest where a
// spindle event or an M0 stands in the program, resumes from there and ends where it should,
// with every programmed move counted.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

TEST_F(MachineTest, BlendedProgramRestsAtEventsAndStopsAndEndsInPlace) {
  ready_machine();
  const auto program = dir_.write("corners.ngc",
                                  "G21 G90 G64 P0.05\n"
                                  "G1 F3000 X10\n"
                                  "Y10\n"
                                  "M3 S1000\n"
                                  "X0\n"
                                  "Y5\n"
                                  "M0\n"
                                  "Y0\n"
                                  "X5\n"
                                  "M2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  json s = wait_until([](const json& st) { return st["exec"] != "running"; });
  // At the M0 the machine stands exactly at the end of the move before it, all moves done.
  ASSERT_EQ(s["exec"], "paused") << s.dump();
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_EQ(s["position"]["commanded"]["x"], 0.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 5.0);
  EXPECT_EQ(s["program"]["moves"], 4);
  EXPECT_EQ(s["spindle"]["direction"], 1);
  result_of(call("program.resume"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["program"]["moves"], 6);
  EXPECT_EQ(s["position"]["commanded"]["x"], 5.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 0.0);
}

TEST_F(MachineTest, MdiLineOfBlendedMovesEndsAtItsEnd) {
  ready_machine();
  const json r = call("mdi.execute", {{"line", "G64 G1 F6000 X3 Y4"}});
  ASSERT_TRUE(r.contains("result")) << r.dump();
  const json s = status();
  EXPECT_EQ(s["position"]["commanded"]["x"], 3.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 4.0);
  EXPECT_EQ(s["motion"], "idle");
}

}  // namespace
}  // namespace cncd::test
