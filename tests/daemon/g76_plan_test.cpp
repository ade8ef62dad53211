// G76 as the daemon runs it on the sim lathe (config/examples/sim_lathe.ini), in the plan
// simulation (the daemon's pipeline, planner and servo loop in virtual time): an M12x1.75
// outside thread (tests/golden/lathe_g76_m12, R1.5 Q29.5 H1) runs to its end; every pass cuts
// at the depth and from the start rs274 prints for it (its golden canon), and, past the
// start's catch-up and before the end's braking, stays within pitch x 0.02 of the helix the
// spindle's position gives: z = start - pitch x (revolutions - the index it started at), one
// helix for all passes but for the shift of their starts along Z by the compound angle.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

constexpr double kPitch = 1.75;
constexpr double kPeaks = 6.0;  // X7 less I1: the radius of the thread's peaks

// One pass as rs274 prints it: the cut's X, where the thread starts and where it ends.
struct GoldenPass {
  double x = 0, start_z = 0, end_z = 0;
};

// The thread feeds of the golden canon: each STRAIGHT_FEED after START_SPEED_FEED_SYNC at the
// pitch, with the traverse to its start before it.
std::vector<GoldenPass> golden_passes(const std::string& canon) {
  std::vector<GoldenPass> passes;
  std::istringstream lines(canon);
  std::string line;
  double x = 0, y = 0, z = 0, last_z = 0;
  bool at_pitch = false;
  while (std::getline(lines, line)) {
    if (std::sscanf(line.c_str(), "STRAIGHT_TRAVERSE(%lf, %lf, %lf", &x, &y, &z) == 3) {
      last_z = z;
    } else if (line == "START_SPEED_FEED_SYNC(1.750000,0)") {
      at_pitch = true;
    } else if (at_pitch &&
               std::sscanf(line.c_str(), "STRAIGHT_FEED(%lf, %lf, %lf", &x, &y, &z) == 3) {
      passes.push_back({x, last_z, z});
      at_pitch = false;
    }
  }
  return passes;
}

// A pass found in the trajectory: a run of samples at one X below the peaks.
struct SimPass {
  double x = 0, start_z = 0, end_z = 0;
  double helix_error = 0;  // the largest, over the part checked
  int checked = 0;         // samples checked against the helix
};

struct Sample {
  double x, z, revolutions;
};

// Runs of at least 0.2 s (a pass takes a second) at one X below the peaks; the moves in and out
// cross that X without stopping.
std::vector<SimPass> sim_passes(const std::vector<Sample>& samples) {
  std::vector<SimPass> passes;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (!(samples[k].x < kPeaks - 1e-9)) continue;
    std::size_t end = k;
    while (end + 1 < samples.size() && samples[end + 1].x == samples[k].x)
      ++end;
    if (end - k < 200) {
      k = end;
      continue;
    }
    SimPass pass;
    pass.x = samples[k].x;
    pass.start_z = samples[k].z;
    pass.end_z = samples[end].z;
    // On the helix: (start - z) / pitch - revolutions is a whole number, the index the thread
    // started at; checked from two revolutions after the tool starts to move until a pitch
    // before the end.
    double moved_at = -1;
    for (std::size_t j = k; j <= end; ++j) {
      const Sample& s = samples[j];
      if (moved_at < 0 && s.z != pass.start_z) moved_at = s.revolutions;
      if (moved_at < 0 || s.revolutions < moved_at + 2 || s.z < pass.end_z + kPitch) continue;
      const double turns = (pass.start_z - s.z) / kPitch - s.revolutions;
      pass.helix_error = std::max(pass.helix_error, std::abs(turns - std::round(turns)) * kPitch);
      ++pass.checked;
    }
    passes.push_back(pass);
    k = end;
  }
  return passes;
}

TEST(G76Plan, AnM12ThreadOnTheSimLatheFollowsTheSpindleAtRs274sDepths) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path(), "sim_lathe");
  const auto loaded = config::load_machine_config(ini);
  ASSERT_TRUE(loaded.ok());
  const std::string golden = std::string(CNCD_SOURCE_DIR) + "/tests/golden/lathe_g76_m12/";
  pipeline::PlanSimOptions options;
  options.interp = pipeline::interpreter_options(*loaded.config);
  options.start_machine = interp::Pose{};
  std::vector<Sample> samples;
  options.on_sample = [&](double, const motion::AxisPose& p, double revolutions) {
    samples.push_back({p[0], p[2], revolutions});
  };
  const auto r = pipeline::simulate_plan(*loaded.config, golden + "program.ngc", options);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());

  const auto expected = golden_passes(slurp(golden + "expected.canon"));
  // J0.2 x n^(1/1.5) short of K1.07 for n = 1..12, the full depth, one spring pass.
  ASSERT_EQ(expected.size(), 14u);
  const auto found = sim_passes(samples);

  ASSERT_EQ(found.size(), expected.size());
  for (std::size_t n = 0; n < found.size(); ++n) {
    SCOPED_TRACE("pass " + std::to_string(n + 1));
    // rs274 prints four decimals.
    EXPECT_NEAR(found[n].x, expected[n].x, 5e-5);
    EXPECT_NEAR(found[n].start_z, expected[n].start_z, 5e-5);
    EXPECT_NEAR(found[n].end_z, expected[n].end_z, 5e-5);
    if (n < 12) {
      const double depth = 0.2 * std::pow(static_cast<double>(n + 1), 1 / 1.5);
      EXPECT_NEAR(found[n].x, kPeaks - depth, 1e-9);
      EXPECT_NEAR(found[n].start_z, 3 - depth * std::tan(29.5 * M_PI / 180), 1e-9);
    } else {
      EXPECT_NEAR(found[n].x, kPeaks - 1.07, 1e-9);
    }
    // The 23 mm at 23.3 mm/s less the catch-up and the braking: hundreds of samples (1 ms).
    EXPECT_GT(found[n].checked, 500);
    EXPECT_LE(found[n].helix_error, kPitch * 0.02);
  }
  // The tool ends back on the drive line, then X20.
  EXPECT_NEAR(samples.back().x, 20, 1e-9);
  EXPECT_NEAR(samples.back().z, -20, 1e-9);
}

// A thread with a tapered exit (E8 L2): each pass is a G33 move along Z and a taper out from
// Z-12 to Z-20 (per revolution 1.75 / cos of the taper's angle, so Z keeps the pitch). The taper
// goes on along the straight part's helix: past the corner, where the tool comes to rest and
// catches up again, it stays within pitch x 0.02 of the same helix (before, it waited for the
// next index and cut a helix shifted by the straight part's length modulo the pitch).
TEST(G76Plan, ATaperedExitStaysOnTheHelixOfItsPass) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path(), "sim_lathe");
  const auto loaded = config::load_machine_config(ini);
  ASSERT_TRUE(loaded.ok());
  const auto program = dir.write("taper.ngc",
                                 "G18 G21 G90\nS800 M3\nG0 X7 Z3\n"
                                 "G76 P1.75 Z-20 I-1 J0.2 K1.07 Q29.5 H1 E8 L2\nG0 X20\nM5\nM2\n");
  pipeline::PlanSimOptions options;
  options.interp = pipeline::interpreter_options(*loaded.config);
  options.start_machine = interp::Pose{7, 0, 3};
  std::vector<Sample> samples;
  options.on_sample = [&](double, const motion::AxisPose& p, double revolutions) {
    samples.push_back({p[0], p[2], revolutions});
  };
  const auto r = pipeline::simulate_plan(*loaded.config, program.string(), options);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());

  // A pass: from the infeed below X7 (the drive line) to the retract back to it. Its helix is
  // where the tool stands along Z at each revolution, taken two revolutions after it starts to
  // move along Z; the rest of the pass is measured against it.
  int passes = 0, straight = 0, taper = 0;
  double straight_error = 0, taper_error = 0, last_z = 0, moved_at = -1, helix = 0;
  bool in_pass = false, have_helix = false;
  for (const Sample& s : samples) {
    if (!(s.x < 7 - 1e-9)) {
      in_pass = false;
      continue;
    }
    if (!in_pass) {
      in_pass = true;
      ++passes;
      moved_at = -1;
      last_z = s.z;
      have_helix = false;
    }
    if (moved_at < 0 && s.z < last_z && s.x < kPeaks) moved_at = s.revolutions;
    last_z = s.z;
    if (moved_at < 0 || s.revolutions < moved_at + 2) continue;
    const double turns = -s.z / kPitch - s.revolutions;
    if (!have_helix) helix = turns;
    have_helix = true;
    const double error = std::abs(turns - helix - std::round(turns - helix)) * kPitch;
    // Clear of the corner at Z-12 (a pitch before, one and a half after) and of the end.
    if (s.z > -12 + kPitch) {
      straight_error = std::max(straight_error, error);
      ++straight;
    } else if (s.z < -12 - 1.5 * kPitch && s.z > -20 + kPitch) {
      taper_error = std::max(taper_error, error);
      ++taper;
    }
  }
  EXPECT_EQ(passes, 7);
  EXPECT_GT(straight, 7 * 300);
  EXPECT_GT(taper, 7 * 100);
  EXPECT_LE(straight_error, kPitch * 0.02);
  EXPECT_LE(taper_error, kPitch * 0.02);
  std::printf("helix: straight %.4f mm (%d samples), taper %.4f mm (%d samples)\n", straight_error,
              straight, taper_error, taper);
}

}  // namespace
}  // namespace cncd::test
