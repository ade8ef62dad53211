// Canned cycles in the UVW planes (G17.1, G18.1, G19.1) through the plan simulation: on a
// machine with U, V and W axes the cycle drills along W (UV plane) and comes back up; on the
// XYZ example mill the program is refused at the first move of an axis it lacks.
#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

std::string example(const std::string& name) {
  return std::string(CNCD_SOURCE_DIR) + "/config/examples/" + name;
}

// The example mill with U, V and W added, each driven by a joint of its own.
std::string six_axis_ini() {
  std::ifstream in(example("sim_mm.ini"));
  std::stringstream text;
  text << in.rdbuf();
  std::string ini = text.str();
  auto replace = [&ini](const std::string& from, const std::string& to) {
    const auto at = ini.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    ini.replace(at, from.size(), to);
  };
  replace("COORDINATES = X Y Z", "COORDINATES = X Y Z U V W");
  replace("coordinates=XYZ", "coordinates=XYZUVW");
  replace("JOINTS = 3", "JOINTS = 6");
  replace("PARAMETER_FILE = sim_mm.var\n", "");
  replace("TOOL_TABLE = sim_mm.tbl\n", "");
  int joint = 3;
  for (const char axis : {'U', 'V', 'W'}) {
    ini += std::string("\n[AXIS_") + axis +
           "]\nMIN_LIMIT = -50\nMAX_LIMIT = 50\nMAX_VELOCITY = 100\nMAX_ACCELERATION = 1000\n";
    ini += "\n[JOINT_" + std::to_string(joint++) +
           "]\nTYPE = LINEAR\nDRIVER = sim\nMIN_LIMIT = -50\nMAX_LIMIT = 50\nMAX_VELOCITY = 100\n"
           "MAX_ACCELERATION = 1000\nFERROR = 1\nMIN_FERROR = 0.25\nHOME = 0\nHOME_SEARCH_VEL = "
           "0\nHOME_LATCH_VEL = 0\nHOME_SEQUENCE = 1\n";
  }
  return ini;
}

constexpr const char* kProgram =
    "G21 G90 F300\nG0 X1\nG17.1\nG81 U10 V20 W-4 R2\nG80\nG18\nG0 X2\nM2\n";

class UvwPlan : public ::testing::Test {
 protected:
  TempDir dir_;
};

TEST_F(UvwPlan, ACycleInTheUvPlaneDrillsAlongWOnAMachineWithUvwAxes) {
  const auto ini = dir_.write("six.ini", six_axis_ini());
  const auto program = dir_.write("uv.ngc", kProgram);
  const auto csv = dir_.path() / "t.csv";
  const auto r = run_command({CNCD_CHECK_BINARY, "--plan", "--trajectory", csv.string(), "--ini",
                              ini.string(), program.string()});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  std::ifstream in(csv);
  std::string row;
  std::getline(in, row);
  ASSERT_EQ(row, "t,x,y,z,u,v,w,spindle,j0,j1,j2,j3,j4,j5");
  double deepest = 1e9;
  std::array<double, 3> at_bottom{};  // U V Z
  double t, x, y, z, u, v, w, spindle;
  while (std::getline(in, row)) {
    ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &t, &x, &y, &z, &u, &v,
                          &w, &spindle),
              8)
        << row;
    if (w < deepest) {
      deepest = w;
      at_bottom = {u, v, z};
    }
  }
  EXPECT_NEAR(deepest, -4, 1e-4);
  // The hole is drilled at U10 V20 with X, Y and Z where they stood.
  EXPECT_NEAR(at_bottom[0], 10, 1e-9);
  EXPECT_NEAR(at_bottom[1], 20, 1e-9);
  EXPECT_NEAR(at_bottom[2], 0, 1e-9);
  // The last sample: back up at R (G99), then X2.
  EXPECT_NEAR(w, 2, 1e-9);
  EXPECT_NEAR(x, 2, 1e-9);
  EXPECT_NEAR(u, 10, 1e-9);
}

TEST_F(UvwPlan, AMachineWithoutTheAxesRefusesTheCycleAtItsLine) {
  const auto program = dir_.write("uv.ngc", kProgram);
  const auto r = run_command({CNCD_CHECK_BINARY, "--ini", example("sim_mm.ini"), program.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("uv.ngc:4: the move commands W, an axis this machine does not have "
                       "([TRAJ] COORDINATES = XYZ)"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace cncd::test
