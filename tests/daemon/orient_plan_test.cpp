// M19 as cncd-check sees it: a spindle without position feedback (a VFD over Modbus without a
// position register, a PWM spindle without an encoder) refuses the program at the M19 line,
// before anything moves; the plan simulation of the sim mill orients the spindle and leaves it
// at the angle, the way P asks.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

std::string example(const std::string& name) {
  return std::string(CNCD_SOURCE_DIR) + "/config/examples/" + name;
}

class OrientPlan : public ::testing::Test {
 protected:
  CommandResult check(const std::string& ini, const std::string& text) {
    const auto program = dir_.write("orient.ngc", text);
    return run_command({CNCD_CHECK_BINARY, "--ini", example(ini), program.string()});
  }
  TempDir dir_;
};

TEST_F(OrientPlan, AModbusSpindleWithoutPositionRefusesM19AtItsLine) {
  const auto r = check("modbus_delta_vfd_e.ini", "G21 G90\nM3 S600\nM19 R90\nG0 X5\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("orient.ngc:3: spindle orientation (M19, G87) needs the spindle's "
                       "position: the Modbus spindle ([SPINDLE_0] DRIVER = modbus) has no "
                       "POSITION_REGISTER"),
            std::string::npos)
      << r.err;
}

TEST_F(OrientPlan, APwmSpindleWithoutEncoderRefusesTheBackBoreThatOrientsIt) {
  const auto r = check("gpio_vcd_mill.ini",
                       "G21 G90 F100\nG0 X10 Y10 Z5\nM3 S600\nG87 Z-5 R2 I1 J0 K-2\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("orient.ngc:4: spindle orientation (M19, G87) needs the spindle's "
                       "position: [SPINDLE_0] has no encoder (ENCODER_A, ENCODER_B, ENCODER_PPR)"),
            std::string::npos)
      << r.err;
}

TEST_F(OrientPlan, TheSimSpindleStopsAtTheAngleTurningTheWayPAsks) {
  // P1: in reverse, so the position falls from where the spindle came to rest to 270 degrees.
  const auto program =
      dir_.write("orient.ngc", "G21 G90\nM3 S600\nG4 P0.5\nM19 R270 P1 Q10\nG1 X10 F600\nM2\n");
  const auto csv = dir_.path() / "t.csv";
  const auto r = run_command({CNCD_CHECK_BINARY, "--plan", "--trajectory", csv.string(), "--ini",
                              example("sim_mm.ini"), program.string()});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  std::ifstream in(csv);
  std::string row;
  std::getline(in, row);
  ASSERT_EQ(row, "t,x,y,z,spindle,j0,j1,j2");
  double t, x, y, z, turns;
  double highest = -1e9;  // where the spindle stood, at most, before X moved
  double at_move = 0;
  bool moved = false;
  bool fell = false;
  double last = 0;
  while (std::getline(in, row)) {
    ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf", &t, &x, &y, &z, &turns), 5) << row;
    if (x < 1e-9) {
      highest = std::max(highest, turns);
      if (turns < last - 1e-9) fell = true;
      last = turns;
    } else if (!moved) {
      moved = true;
      at_move = turns;
    }
  }
  ASSERT_TRUE(moved);
  EXPECT_TRUE(fell);
  EXPECT_NEAR(std::remainder(at_move - 0.75, 1.0), 0, 0.5 / 360);
  EXPECT_LE(highest - at_move, 1.0);  // less than a turn back
}

}  // namespace
}  // namespace cncd::test
