// cncd-check --plan on machines whose joints are not their axes: the peak joint velocity and
// acceleration against each [JOINT_n]'s limits beside the axes' (text and JSON;
// config/examples/sim_corexy.ini).
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cncd_check_fixture.hpp"

namespace cncd::test {
namespace {

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

}  // namespace
}  // namespace cncd::test
