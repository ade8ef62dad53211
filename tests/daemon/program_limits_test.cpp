// program.open refuses a program whose moves leave the soft limits, naming the line and the
// axis, from where the machine is and with its offsets; nothing moves.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

TEST_F(MachineTest, OpenRefusesAProgramBeyondTheSoftLimits) {
  const auto program = dir_.write("far.ngc", "G21 G90\nG0 X10 Y10\nG1 X320 F600\nG0 X0\nM2\n");
  const json r = call("program.open", {{"path", program.string()}});
  EXPECT_EQ(error_code(r), 1003);
  const std::string message = r["error"].value("message", "");
  EXPECT_NE(message.find(program.string() + ":3: feed move: X 320.0000 is above [AXIS_X] "
                                            "MAX_LIMIT 300.0000"),
            std::string::npos)
      << message;
  // Nothing is open: there is nothing to run.
  EXPECT_EQ(error_code(call("program.run")), 1003);
}

TEST_F(MachineTest, OpenRefusesAnArcThatBulgesPastALimit) {
  const auto program =
      dir_.write("arc.ngc", "G21 G90\nG0 X100 Y160\nG2 X200 Y160 I50 J0 F600\nM2\n");
  const json r = call("program.open", {{"path", program.string()}});
  EXPECT_EQ(error_code(r), 1003);
  EXPECT_NE(r["error"].value("message", "").find(":3: arc: Y 210.0000 is above [AXIS_Y]"),
            std::string::npos)
      << r.dump();
}

TEST_F(MachineTest, OpenChecksWithTheMachinesOffsetsAndRunsAProgramWithinTheLimits) {
  ready_machine();
  const auto program = dir_.write("part.ngc", "G21 G90\nG0 X40 Y5\nG1 X60 F1200\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  // With G54 moved to X250 the same program reaches machine X310.
  mdi("G10 L2 P1 X250");
  const json r = call("program.open", {{"path", program.string()}});
  EXPECT_EQ(error_code(r), 1003);
  EXPECT_NE(r["error"].value("message", "").find(":3: feed move: X 310.0000 is above"),
            std::string::npos)
      << r.dump();
  mdi("G10 L2 P1 X0");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
}

}  // namespace
}  // namespace cncd::test
