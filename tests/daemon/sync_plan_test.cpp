// Rigid tapping and threading as the daemon runs them, in the plan simulation (the daemon's
// pipeline, planner and servo loop on the simulated machine, in virtual time), with the sim
// spindle ramping at 3000 rpm/s: G33.1 Z-10 K1.25 at S600, a rigid G84 cycle with R and L, the
// Numeryx g74 and examples/rigid_tap.ngc. At every sample of every tap the axis stays within
// pitch x 0.02 of the helix the spindle's position gives, the tap reaches its bottom and comes
// back to where it started, and the spindle turns forward again after it.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

struct Sample {
  double t;
  double x, y, z;
  double revolutions;
};

// One tap found in a trajectory: the samples below its start height at one XY.
struct Tap {
  double x = 0, y = 0;
  double top = 0;     // where it started and must end
  double bottom = 0;  // the deepest sample
  double helix_error = 0;
  std::size_t first = 0, last = 0;  // sample indexes of the run below `top`
};

class SyncPlan : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path());
    std::stringstream text;
    {
      std::ifstream in(ini_);
      text << in.rdbuf();
    }
    std::string ini = text.str();
    const auto ramp = ini.find("\nACCELERATION = 6000");
    ASSERT_NE(ramp, std::string::npos);
    ini.replace(ramp, 20, "\nACCELERATION = 3000");
    const auto section = ini.find("[RS274NGC]\n");
    ASSERT_NE(section, std::string::npos);
    ini.insert(section + 11, "RIGID_TAPPING = 1\n");
    std::ofstream(ini_) << ini;
    loaded_ = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded_.ok());
    ASSERT_EQ(loaded_.config->spindle.acceleration, 3000);
    ASSERT_TRUE(loaded_.config->rigid_tapping);
  }

  pipeline::PlanSimResult simulate(const std::filesystem::path& program) {
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(*loaded_.config);
    options.start_machine = interp::Pose{};
    samples_.clear();
    options.on_sample = [&](double t, const motion::AxisPose& p, double revolutions) {
      samples_.push_back({t, p[0], p[1], p[2], revolutions});
    };
    auto r = pipeline::simulate_plan(*loaded_.config, program, options);
    EXPECT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
    return r;
  }
  pipeline::PlanSimResult simulate(const std::string& name, const std::string& program) {
    return simulate(dir_.write(name, program));
  }

  // The taps in the trajectory: runs of samples below `top` (the height each tap starts at)
  // at a fixed XY, with their helix error against the spindle: z_ideal = top - pitch *
  // direction * (revolutions - locked), `locked` the spindle's position at rest before the run.
  std::vector<Tap> taps(double top, double pitch, int direction = 1) const {
    std::vector<Tap> found;
    for (std::size_t k = 1; k < samples_.size(); ++k) {
      if (!(samples_[k].z < top - 1e-9) || samples_[k - 1].z < top - 1e-9) continue;
      Tap tap;
      tap.x = samples_[k].x;
      tap.y = samples_[k].y;
      tap.top = samples_[k - 1].z;
      tap.first = k;
      const double locked = samples_[k - 1].revolutions;
      tap.bottom = samples_[k].z;
      std::size_t j = k;
      for (; j < samples_.size() && samples_[j].z < top - 1e-9; ++j) {
        const Sample& s = samples_[j];
        EXPECT_EQ(s.x, tap.x);
        EXPECT_EQ(s.y, tap.y);
        tap.bottom = std::min(tap.bottom, s.z);
        const double ideal = top - pitch * direction * (s.revolutions - locked);
        tap.helix_error = std::max(tap.helix_error, std::abs(s.z - ideal));
      }
      tap.last = j - 1;
      found.push_back(tap);
      k = j;
    }
    return found;
  }

  void expect_tap(const Tap& tap, double x, double y, double top, double bottom, double pitch) {
    SCOPED_TRACE("tap at X" + std::to_string(x) + " Y" + std::to_string(y));
    EXPECT_NEAR(tap.x, x, 1e-9);
    EXPECT_NEAR(tap.y, y, 1e-9);
    EXPECT_NEAR(tap.top, top, 1e-9);
    EXPECT_NEAR(tap.bottom, bottom, 0.002);
    EXPECT_LE(tap.helix_error, pitch * 0.02);
    // It comes back to where it started.
    ASSERT_LT(tap.last + 1, samples_.size());
    EXPECT_NEAR(samples_[tap.last + 1].z, top, 1e-9);
  }

  TempDir dir_;
  std::filesystem::path ini_;
  config::LoadResult loaded_;
  std::vector<Sample> samples_;
};

TEST_F(SyncPlan, G33_1StaysOnTheHelixAndTheSpindleTurnsForwardAgain) {
  const auto r =
      simulate("tap.ngc", "G21 G90 G17\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-10 K1.25\nG0 Z20\nM2\n");
  const auto found = taps(5, 1.25);
  ASSERT_EQ(found.size(), 1u);
  expect_tap(found[0], 10, 10, 5, -10, 1.25);
  // 15 mm down and back at 600 rpm x 1.25 mm is 2.4 s, plus the spindle's ramps.
  const double tap_s = samples_[found[0].last].t - samples_[found[0].first].t;
  EXPECT_GT(tap_s, 2.4);
  EXPECT_LT(tap_s, 3.4);
  EXPECT_GT(r.cycle_time_s, tap_s);
  // The tap's bound counts it both ways.
  EXPECT_GT(r.feed_bound_s, 2.4);
  // After the tap the spindle turns forward again (M2 stops it at the end).
  EXPECT_GT(samples_.back().revolutions, samples_[found[0].last + 1].revolutions + 0.1);
}

TEST_F(SyncPlan, RigidG84WithRAndLTapsEveryHoleOnTheHelix) {
  // G94: the pitch is F/S = 750 / 600 = 1.25 mm. G91: three holes 10 mm apart, R 7 below the
  // start, the bottom 8 below R; G98 back to the start height between them.
  simulate("g84.ngc",
           "G21 G90 G17\nG0 X0 Y0 Z10\nM3 S600\nG91 G98 G84 X10 Z-8 R-7 L3 F750\n"
           "G80 G90\nM2\n");
  const auto found = taps(3, 1.25);
  ASSERT_EQ(found.size(), 3u);
  for (int n = 0; n < 3; ++n)
    expect_tap(found[static_cast<std::size_t>(n)], 10.0 * (n + 1), 0, 3, -5, 1.25);
  // Between the holes the tool went back up to the start height.
  double highest = -1e9;
  for (std::size_t k = found[0].last; k < found[1].first; ++k)
    highest = std::max(highest, samples_[k].z);
  EXPECT_NEAR(highest, 10, 1e-9);
}

TEST_F(SyncPlan, NumeryxG74IsAlwaysRigid) {
  const auto r =
      simulate(std::filesystem::path(CNCD_SOURCE_DIR) / "examples/numeryx/rigid_tap.ngc");
  const auto found = taps(3, 1.25);  // R1 = R + 1 mm
  ASSERT_EQ(found.size(), 3u);
  for (int n = 0; n < 3; ++n)
    expect_tap(found[static_cast<std::size_t>(n)], 20.0 + 20.0 * n, 20, 3, -14, 1.25);
  EXPECT_TRUE(r.complete());
}

TEST_F(SyncPlan, TheRigidTapExampleRuns) {
  simulate(std::filesystem::path(CNCD_SOURCE_DIR) / "examples/rigid_tap.ngc");
  // G33.1 from Z5, then the G84 holes from R2.
  const auto from_five = taps(5, 1.0);
  ASSERT_GE(from_five.size(), 1u);
  expect_tap(from_five[0], 10, 10, 5, -12, 1.0);
  const auto from_r = taps(2, 1.0);
  ASSERT_EQ(from_r.size(), 3u);
  expect_tap(from_r[1], 25, 10, 2, -12, 1.0);
  expect_tap(from_r[2], 40, 10, 2, -12, 1.0);
}

TEST_F(SyncPlan, CncdCheckTrajectoryHasTheSpindleColumn) {
  const auto program =
      dir_.write("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-2 K1.25\nM2\n");
  const auto csv = dir_.path() / "tap.csv";
  const auto r = run_command({CNCD_CHECK_BINARY, "--plan", "--trajectory", csv.string(), "--ini",
                              ini_.string(), program.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "t,x,y,z,spindle,j0,j1,j2");
  // Read back, the rows give the same helix.
  std::string row;
  while (std::getline(in, row)) {
    Sample s{};
    ASSERT_EQ(
        std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf", &s.t, &s.x, &s.y, &s.z, &s.revolutions), 5)
        << row;
    samples_.push_back(s);
  }
  const auto found = taps(5, 1.25);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LE(found[0].helix_error, 0.025);
  EXPECT_NEAR(found[0].bottom, -2, 0.002);
}

TEST_F(SyncPlan, AMachineWithoutTheSpindlesPositionRefusesSynchronizedMotion) {
  // The Delta VFD-E example reports the spindle's speed, not its position.
  const auto program =
      dir_.write("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-2 K1.25\nM2\n");
  const auto r = run_command(
      {CNCD_CHECK_BINARY, "--ini",
       std::string(CNCD_SOURCE_DIR) + "/config/examples/modbus_delta_vfd_e.ini", program.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("tap.ngc:4: spindle-synchronized motion (G33, G33.1, rigid tapping) needs "
                       "the spindle's position: the Modbus spindle ([SPINDLE_0] DRIVER = modbus) "
                       "has no POSITION_REGISTER"),
            std::string::npos)
      << r.err;
}

// K x S beyond an axis's MAX_VELOCITY: the thread would fall behind the spindle. A tap or a
// G95 feed at the same speeds is no such problem: the tap drives the spindle no faster than
// the axis follows, and a feed runs at the axis's limit.
TEST_F(SyncPlan, AThreadTheAxisCannotFollowIsRefusedAtItsLineWithTheSpeeds) {
  const auto check = [&](const std::string& name, const std::string& program) {
    return run_command(
        {CNCD_CHECK_BINARY, "--ini", ini_.string(), dir_.write(name, program).string()});
  };
  const auto fast = check("fast.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S6000\nG33 Z-10 K100\nM2\n");
  EXPECT_EQ(fast.exit_status, 1);
  EXPECT_NE(fast.err.find("fast.ngc:4: G33 at S6000 with 100 mm per revolution needs Z at 10000 "
                          "mm/s; [AXIS_Z] MAX_VELOCITY is 100 mm/s: the thread would fall behind "
                          "the spindle (at most 60 rpm at this pitch, or at most 1 mm per "
                          "revolution at this speed)"),
            std::string::npos)
      << fast.err;
  // A taper: X and Z share the path speed; X's share is over its 200 mm/s.
  const auto taper = check("taper.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S3000\nG33 X50 Z2 K5\nM2\n");
  EXPECT_EQ(taper.exit_status, 1);
  EXPECT_NE(taper.err.find("taper.ngc:4: G33 at S3000 with 5 mm per revolution needs X at "),
            std::string::npos)
      << taper.err;
  EXPECT_NE(taper.err.find("[AXIS_X] MAX_VELOCITY is 200 mm/s"), std::string::npos) << taper.err;
  // Within the limit (1.5 mm x 60 rev/s = 90 mm/s), it passes.
  const auto ok = check("ok.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S3600\nG33 Z-10 K1.5\nM2\n");
  EXPECT_EQ(ok.exit_status, 0) << ok.err;
  const auto tap = check("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S6000\nG33.1 Z-10 K2\nM2\n");
  EXPECT_EQ(tap.exit_status, 0) << tap.err;
  const auto g95 = check("g95.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S6000\nG95 G1 Z-10 F2\nM2\n");
  EXPECT_EQ(g95.exit_status, 0) << g95.err;
}

TEST_F(SyncPlan, ASpindleThatCannotReverseRefusesRigidTappingButThreads) {
  std::string ini;
  {
    std::ifstream in(ini_);
    std::stringstream text;
    text << in.rdbuf();
    ini = text.str();
  }
  const auto section = ini.find("[SPINDLE_0]\n");
  ASSERT_NE(section, std::string::npos);
  ini.insert(section + 12, "MAX_REVERSE_VELOCITY = 0\n");
  std::ofstream(ini_) << ini;
  const auto check = [&](const std::string& name, const std::string& program) {
    return run_command(
        {CNCD_CHECK_BINARY, "--ini", ini_.string(), dir_.write(name, program).string()});
  };
  const auto tap = check("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-2 K1.25\nM2\n");
  EXPECT_EQ(tap.exit_status, 1);
  EXPECT_NE(tap.err.find("tap.ngc:4: rigid tapping turns the spindle back out of the hole, and "
                         "[SPINDLE_0] MAX_REVERSE_VELOCITY = 0 forbids reverse"),
            std::string::npos)
      << tap.err;
  // RIGID_TAPPING = 1 makes G84 such a tap too.
  const auto g84 =
      check("g84.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG95 G84 Z-2 R2 F1.25\nG80\nM2\n");
  EXPECT_EQ(g84.exit_status, 1);
  EXPECT_NE(g84.err.find("g84.ngc:4: rigid tapping turns the spindle back"), std::string::npos)
      << g84.err;
  // A thread turns one way only.
  const auto thread = check("thread.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33 Z-2 K1.25\nM2\n");
  EXPECT_EQ(thread.exit_status, 0) << thread.err;
}

}  // namespace
}  // namespace cncd::test
