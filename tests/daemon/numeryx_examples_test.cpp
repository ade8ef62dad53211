// examples/numeryx: the note's cycle formats and hole patterns on the simulated machine. Each
// program's holes are worked out by hand; the plan simulation (the daemon's pipeline, planner
// and servo loop in virtual time) must drill each one from R1 to its bottom at the feed and
// leave it at the retract height; the daemon runs the cycle formats to their end.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

const std::string kNumeryx = std::string(CNCD_SOURCE_DIR) + "/examples/numeryx/";

struct ExpectedHole {
  double x, y;  // mm
  double r1;    // where the feed starts
  double bottom;
  double retract;  // the height the tool leaves at
  double feed;     // mm/s
};

struct Sample {
  double t;
  double x, y, z;
};

class NumeryxExamples : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path());
    loaded_ = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded_.ok());
  }

  std::vector<Sample> trajectory(const std::string& program) {
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(*loaded_.config);
    options.measure = false;
    std::vector<Sample> samples;
    options.on_sample = [&](double t, const motion::AxisPose& p, double) {
      samples.push_back({t, p[0], p[1], p[2]});
    };
    const auto r = pipeline::simulate_plan(*loaded_.config, kNumeryx + program, options);
    EXPECT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
    return samples;
  }

  // At each hole's XY: the lowest Z is the bottom, the highest the retract height, and below
  // R1 the tool moves no faster than the feed, while above it (the rapid down) it does.
  void expect_holes(const std::string& program, const std::vector<ExpectedHole>& holes) {
    SCOPED_TRACE(program);
    const auto samples = trajectory(program);
    ASSERT_GT(samples.size(), 2U);
    for (std::size_t n = 0; n < holes.size(); ++n) {
      SCOPED_TRACE("hole " + std::to_string(n + 1));
      const ExpectedHole& h = holes[n];
      double low = 1e9;
      double high = -1e9;
      double fastest_below_r1 = 0;
      double fastest_above_r1 = 0;
      int count = 0;
      for (std::size_t i = 1; i < samples.size(); ++i) {
        const Sample& s = samples[i];
        const Sample& before = samples[i - 1];
        if (std::abs(s.x - h.x) > 1e-6 || std::abs(s.y - h.y) > 1e-6) continue;
        if (std::abs(before.x - h.x) > 1e-6 || std::abs(before.y - h.y) > 1e-6) continue;
        ++count;
        low = std::min(low, s.z);
        high = std::max(high, s.z);
        const double speed = std::abs(s.z - before.z) / (s.t - before.t);
        if (s.z < before.z && before.z < h.r1 - 1e-6) {
          fastest_below_r1 = std::max(fastest_below_r1, speed);
        }
        if (s.z < before.z && s.z > h.r1 + 1e-6) {
          fastest_above_r1 = std::max(fastest_above_r1, speed);
        }
      }
      ASSERT_GT(count, 0) << "no sample at X " << h.x << " Y " << h.y;
      // Samples fall at servo periods: a reversal at the bottom or the top happens between two,
      // within a fraction of a micrometre.
      EXPECT_NEAR(low, h.bottom, 1e-3);
      EXPECT_NEAR(high, h.retract, 1e-3);
      EXPECT_LE(fastest_below_r1, h.feed * 1.0001);
      EXPECT_GT(fastest_above_r1, h.feed * 1.5);
    }
  }

  TempDir dir_;
  std::filesystem::path ini_;
  config::LoadResult loaded_;
};

// Zi 10, g91 R-2 Z-5: R1 = 9, drilled from 8 to 3, back to Zi (g98).
std::vector<ExpectedHole> cycle_format_holes() {
  return {{10, 20, 9, 3, 10, 5}, {30, 20, 9, 3, 10, 5}, {50, 40, 9, 3, 10, 5}};
}

constexpr double kInch = 25.4;
constexpr double kFeed8 = 8 * kInch / 60;  // f8 in inch/min, in mm/s

TEST_F(NumeryxExamples, OneBlockAndTwoBlocksDrillTheSameHoles) {
  expect_holes("one_block.ngc", cycle_format_holes());
  expect_holes("two_blocks.ngc", cycle_format_holes());
}

TEST_F(NumeryxExamples, EightHolesOnASlope) {
  std::vector<ExpectedHole> holes;
  for (int i = 0; i < 8; ++i) {
    holes.push_back({(1 + 0.5 * i) * kInch, (1 + 0.25 * i) * kInch, 0.04 * kInch, -0.3 * kInch,
                     0.5 * kInch, kFeed8});
  }
  expect_holes("slope.ngc", holes);
}

TEST_F(NumeryxExamples, EightHolesOnAPolarSlope) {
  std::vector<ExpectedHole> holes;
  for (int i = 0; i < 8; ++i) {
    const double r = 0.5 + 0.5 * i;
    holes.push_back({(1 + r * std::cos(std::numbers::pi / 6)) * kInch,
                     (1 + r * std::sin(std::numbers::pi / 6)) * kInch, 0.04 * kInch, -0.3 * kInch,
                     0.5 * kInch, kFeed8});
  }
  expect_holes("polar_slope.ngc", holes);
}

TEST_F(NumeryxExamples, ThirteenHoleBoltCircle) {
  std::vector<ExpectedHole> holes;
  for (int i = 1; i <= 13; ++i) {
    const double a = 2 * std::numbers::pi * i / 13;
    holes.push_back({(5 + 4 * std::cos(a)) * kInch, (3.74 + 4 * std::sin(a)) * kInch, 0.04 * kInch,
                     -0.3 * kInch, 0.5 * kInch, kFeed8});
  }
  expect_holes("bolt_circle.ngc", holes);
}

// The daemon reads the dialect from the first line and runs the cycle formats to their end.
class NumeryxDaemon : public MachineTest {};

TEST_F(NumeryxDaemon, RunsBothCycleFormatsOnTheSimMachine) {
  ready_machine();
  for (const char* name : {"one_block.ngc", "two_blocks.ngc"}) {
    SCOPED_TRACE(name);
    result_of(call("program.open", {{"path", kNumeryx + name}}));
    result_of(call("program.run"));
    const auto s = wait_until([](const nlohmann::json& st) {
      return st["exec"] == "idle" && st["program"]["result"] != "running" &&
             st["program"]["result"] != "";
    });
    EXPECT_EQ(s["program"]["result"], "done") << s.dump();
    EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 50, 1e-9);
    EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 40, 1e-9);
    EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 10, 1e-9);
  }
}

}  // namespace
}  // namespace cncd::test
