// cncd-check --plan on machines whose joints are not their axes: the peak joint velocity and
// acceleration against each [JOINT_n]'s limits beside the axes' (text and JSON), and the
// trajectory's joint, tool tip and TCP columns (config/examples/sim_corexy.ini,
// sim_xyzac_trt.ini).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cncd_check_fixture.hpp"

namespace cncd::test {
namespace {

// The rows of a trajectory CSV after its header, as numbers; the header in `header`.
std::vector<std::vector<double>> csv_rows(const std::filesystem::path& path, std::string& header) {
  std::ifstream in(path);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');)
      row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

// The 45-degree diagonal turns joint 0 alone, at its MAX_VELOCITY (300 mm/s, the axes 250):
// the joints' line shows it at 100 %, the axes' line X and Y at 150 mm/s each (the tool at
// 212 mm/s).
constexpr const char* kDiagonal = "G21 G90\nG0 X50 Y50 Z-5\nG0 X0 Y0\nM2\n";

TEST_F(CncdCheck, PlanShowsTheCorexyMotorsBesideTheAxes) {
  const std::string corexy = copy_example_machine(dir_.path(), "sim_corexy").string();
  auto r = check(kDiagonal, {"--plan", "--ini", corexy});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("peak axis velocity (machine coordinates, mm/s, % of [AXIS_L] "
                       "MAX_VELOCITY):  X 150.000 (60.00 %)  Y 150.000 (60.00 %)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("peak joint velocity (mm/s, % of [JOINT_n] MAX_VELOCITY):  J0 300.000 "
                       "(100.00 %)  J1 0.000 (0.00 %)  J2 Z "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("peak joint acceleration (mm/s^2, % of [JOINT_n] MAX_ACCELERATION):  J0 "
                       "3000.000 (100.00 %)"),
            std::string::npos)
      << r.out;

  r = check(kDiagonal, {"--plan", "--json", "--ini", corexy});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["kinematics"], "corexykins");
  const auto& joints = report["joints"];
  ASSERT_EQ(joints.size(), 3u) << joints.dump();
  EXPECT_EQ(joints[0]["joint"], 0);
  EXPECT_TRUE(joints[0]["axis"].is_null());  // X + Y: no axis of its own
  EXPECT_EQ(joints[2]["axis"], "z");
  EXPECT_NEAR(joints[0]["velocity_ratio"].get<double>(), 1.0, 1e-9) << joints.dump();
  EXPECT_NEAR(joints[0]["acceleration_ratio"].get<double>(), 1.0, 1e-6);
  EXPECT_EQ(joints[0]["max_velocity"], 300.0);
  EXPECT_LT(joints[1]["peak_velocity"].get<double>(), 1e-9);
  EXPECT_NEAR(report["axes"]["x"]["peak_velocity"].get<double>(), 150.0, 1e-9);
}

TEST_F(CncdCheck, PlanOnTrivkinsKeepsItsAxisLinesAlone) {
  auto r = check(kDiagonal, {"--plan", "--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("peak velocity (mm/s, % of MAX_VELOCITY):  X "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("peak joint"), std::string::npos) << r.out;
  r = check(kDiagonal, {"--plan", "--json", "--ini", ini_.string()});
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["joints"].size(), 3u);
  EXPECT_EQ(report["joints"][0]["peak_velocity"], report["axes"]["x"]["peak_velocity"]);
}

TEST_F(CncdCheck, TrajectoryHasTheCorexyMotors) {
  const std::string corexy = copy_example_machine(dir_.path(), "sim_corexy").string();
  const auto csv = dir_.path() / "corexy.csv";
  const auto r = check("G21 G90\nG0 X30 Y20 Z-5\nG1 X10 Y40 F3000\nM2\n",
                       {"--plan", "--trajectory", csv.string(), "--ini", corexy});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  const auto rows = csv_rows(csv, header);
  EXPECT_EQ(header, "t,x,y,z,spindle,j0,j1,j2");
  ASSERT_GT(rows.size(), 100u);
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 8u);
    EXPECT_NEAR(row[5], row[1] + row[2], 2e-6);  // j0 = X + Y, to the file's six decimals
    EXPECT_NEAR(row[6], row[1] - row[2], 2e-6);  // j1 = X - Y
    EXPECT_EQ(row[7], row[3]);                   // j2 = Z
  }
  EXPECT_EQ(rows.back()[5], 50.0);
  EXPECT_EQ(rows.back()[6], -30.0);
}

// Under TCP the tip columns hold still while A turns and the joints swing round the A axis;
// the tcp column is 1 from M428's first move to M429's.
TEST_F(CncdCheck, TrajectoryHasTheToolTipAndTheTcpState) {
  const std::string trt = copy_example_machine(dir_.path(), "sim_xyzac_trt").string();
  const auto csv = dir_.path() / "trt.csv";
  const auto r = check(
      "G21 G90 G94\nG0 X40 Y0 Z20 A0 C0\nM428\nG1 A-90 F1800\nG1 A0\nM429\n"
      "G0 X0 Y0\nM2\n",
      {"--plan", "--trajectory", csv.string(), "--ini", trt});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  const auto rows = csv_rows(csv, header);
  ASSERT_EQ(header, "t,x,y,z,a,c,spindle,j0,j1,j2,j3,j4,tip_x,tip_y,tip_z,tip_a,tip_c,tcp");
  double drift = 0;
  double swing = 0;
  int tcp_rows = 0;
  bool tcp_ended = false;
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 18u);
    for (int k = 0; k < 5; ++k)
      EXPECT_EQ(row[7 + k], row[1 + k]);  // joint n drives axis n
    if (row[17] == 1.0) {
      ++tcp_rows;
      EXPECT_FALSE(tcp_ended) << "tcp on again at t " << row[0];
      drift = std::max(drift, std::hypot(row[12] - 40, row[13], row[14] - 20));
      swing = std::max(swing, std::abs(row[2]));
    } else if (tcp_rows > 0) {
      tcp_ended = true;
    }
    EXPECT_EQ(row[15], row[4]);  // the rotaries are the same in both frames
  }
  std::printf(
      "trajectory under TCP: %d periods, tip off X40 Y0 Z20 by %.6f mm at most, the "
      "joints' Y out to %.3f mm\n",
      tcp_rows, drift, swing);
  EXPECT_GT(tcp_rows, 1000);  // two quarter turns at 30 deg/s
  EXPECT_TRUE(tcp_ended);
  EXPECT_LE(drift, 0.005);  // [TRAJ] TCP_TOLERANCE
  EXPECT_GT(swing, 20.0);
  EXPECT_EQ(rows.back()[17], 0.0);
  EXPECT_EQ(rows.back()[12], 0.0);  // at rest where the last move ends, A at 0: tip = axes
}

}  // namespace
}  // namespace cncd::test
