// The offline plan simulation (plan_sim) and cncd-check --plan: cycle time against the bounds
// worked out by hand, peaks within the limits, path deviation, per-move start times, errors
// naming file and line, budgets, the trajectory CSV.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

class PlanSimTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path());
    loaded_ = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded_.ok());
    options_.interp = pipeline::interpreter_options(*loaded_.config);
  }
  const config::MachineConfig& machine() const { return *loaded_.config; }
  pipeline::PlanSimResult simulate(const std::string& program) {
    return pipeline::simulate_plan(machine(), dir_.write("prog.ngc", program), options_);
  }

  TempDir dir_;
  std::filesystem::path ini_;
  config::LoadResult loaded_;
  pipeline::PlanSimOptions options_;
};

TEST_F(PlanSimTest, AStraightFeedTakesItsTrapezoidAndStaysWithinTheLimits) {
  // 10 mm at 10 mm/s, X accelerating at 2000 mm/s^2: 1 s plus 5 ms of ramps.
  const auto r = simulate("G21 G90\nG1 X10 F600\nM2\n");
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  EXPECT_EQ(r.moves, 1u);
  EXPECT_NEAR(r.feed_bound_s, 1.0, 1e-12);
  EXPECT_NEAR(r.exact_stop_bound_s, 1.005, 1e-12);
  EXPECT_GE(r.cycle_time_s, 1.005 - 1e-9);
  EXPECT_LE(r.cycle_time_s, 1.005 + 2 * r.period_s);
  EXPECT_EQ(r.cycles, static_cast<std::uint64_t>(std::llround(r.cycle_time_s / r.period_s)));
  EXPECT_NEAR(r.peak_velocity[0], 10.0, 1e-6);
  EXPECT_LE(r.peak_acceleration[0], 2000.0 * 1.001);
  EXPECT_GE(r.peak_acceleration[0], 1900.0);
  EXPECT_EQ(r.peak_velocity[1], 0.0);
  EXPECT_LT(r.max_deviation, 1e-9);
  ASSERT_EQ(r.move_start_s.size(), 1u);
  EXPECT_EQ(r.move_start_s[0], 0.0);
  EXPECT_EQ(r.move_line[0], 2);
}

// G95: F per revolution at the programmed speed: 0.1 mm x 600 rpm = 1 mm/s over 10 mm.
TEST_F(PlanSimTest, FeedPerRevolutionRunsAtFTimesTheSpindleSpeed) {
  const auto r = simulate("G21 G90\nS600 M3\nG95 G1 X10 F0.1\nG94 G1 X20 F600\nM2\n");
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  EXPECT_NEAR(r.feed_bound_s, 10.0 + 1.0, 1e-9);
  EXPECT_NEAR(r.peak_velocity[0], 10.0, 1e-6);  // the G94 move; the G95 one at 1 mm/s
}

TEST_F(PlanSimTest, RapidsRunAtTheFastestSpeedTheAxesAllowAlongThem) {
  // Diagonal: each axis would allow 200 * sqrt(2) mm/s, [TRAJ] MAX_LINEAR_VELOCITY caps at 250.
  const auto r = simulate("G21 G90\nG0 X100 Y100\nM2\n");
  ASSERT_TRUE(r.complete());
  const double length = std::sqrt(2.0) * 100;
  EXPECT_NEAR(r.feed_bound_s, length / 250, 1e-12);
  EXPECT_NEAR(r.exact_stop_bound_s, length / 250 + 250 / (2000 * std::sqrt(2.0)), 1e-12);
  EXPECT_GE(r.cycle_time_s, r.exact_stop_bound_s - 1e-9);
  EXPECT_LE(r.peak_velocity[0], 200 * 1.001);
  EXPECT_LE(r.peak_acceleration[1], 2000 * 1.001);
}

TEST_F(PlanSimTest, ArcsAndDwellsAreFollowedAndEachMoveGetsItsStartTime) {
  std::vector<double> times;
  options_.on_sample = [&times](double t, const motion::AxisPose&, double) { times.push_back(t); };
  // G61: the traverse stops where the circle starts (under G64 a fillet would round it).
  const auto r =
      simulate("G21 G90 G61\nG0 X20 Y0\nG2 X20 Y0 I-10 J0 F1200\nG4 P0.25\nG1 X30\nM2\n");
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : "");
  ASSERT_EQ(r.moves, 4u);
  EXPECT_EQ(r.move_line, (std::vector<std::int32_t>{2, 3, 4, 5}));
  for (std::size_t i = 1; i < r.move_start_s.size(); ++i)
    EXPECT_GT(r.move_start_s[i], r.move_start_s[i - 1]) << i;
  // The dwell starts when the circle ends and lasts its 0.25 s.
  EXPECT_NEAR(r.move_start_s[3] - r.move_start_s[2], 0.25, 2 * r.period_s);
  // The full circle: 2 pi 10 mm at 20 mm/s is in the feed bound, and so is the dwell.
  const double rapid = 20.0 / 200;
  EXPECT_NEAR(r.feed_bound_s, rapid + 2 * M_PI * 10 / 20 + 0.25 + 10.0 / 20, 1e-9);
  EXPECT_LT(r.max_deviation, 1e-6);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(r.peak_velocity[axis], machine().axes[axis].max_velocity * 1.001);
    EXPECT_LE(r.peak_acceleration[axis], machine().axes[axis].max_acceleration * 1.001);
  }
  ASSERT_EQ(times.size(), r.cycles);
  EXPECT_NEAR(times.back(), r.cycle_time_s, 1e-9);
  EXPECT_NEAR(times.front(), r.period_s, 1e-12);
}

TEST_F(PlanSimTest, BlendedCornersKeepTheProgrammedBoundsAndOneStartTimePerMove) {
  // A 20 mm square at 20 mm/s under G64 P0.1: the bounds are the programmed path's.
  std::vector<motion::Segment> moves;
  options_.on_move = [&moves](const motion::Segment& move) { moves.push_back(move); };
  const auto r = simulate("G21 G90 G64 P0.1\nG1 X20 F1200\nY20\nX0\nY0\nM2\n");
  ASSERT_TRUE(r.complete());
  // Each move as programmed, corner to corner, whatever the blends made of it.
  ASSERT_EQ(moves.size(), 4u);
  const double corners[5][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}, {0, 0}};
  for (std::size_t i = 0; i < moves.size(); ++i) {
    EXPECT_EQ(moves[i].line, static_cast<std::int32_t>(i + 2));
    EXPECT_NEAR(moves[i].length, 20.0, 1e-9);
    EXPECT_NEAR(moves[i].feed, 20.0, 1e-9);
    EXPECT_NEAR(moves[i].start[0], corners[i][0], 1e-9);
    EXPECT_NEAR(moves[i].start[1], corners[i][1], 1e-9);
    EXPECT_NEAR(moves[i].end[0], corners[i + 1][0], 1e-9);
    EXPECT_NEAR(moves[i].end[1], corners[i + 1][1], 1e-9);
  }
  EXPECT_EQ(r.moves, 4u);
  EXPECT_NEAR(r.feed_bound_s, 4.0, 1e-9);
  EXPECT_NEAR(r.exact_stop_bound_s, 4.0 + 4 * 0.01, 1e-9);
  // Blend arcs cut the corners a little short of the programmed 80 mm.
  EXPECT_GE(r.cycle_time_s, r.feed_bound_s * 0.99);
  EXPECT_LT(r.cycle_time_s, r.exact_stop_bound_s + 2 * r.period_s);
  EXPECT_LE(r.max_deviation, 0.1 + 1e-6);
  ASSERT_EQ(r.move_start_s.size(), 4u);
  EXPECT_EQ(r.move_line, (std::vector<std::int32_t>{2, 3, 4, 5}));
  for (std::size_t i = 1; i < r.move_start_s.size(); ++i)
    EXPECT_GT(r.move_start_s[i], r.move_start_s[i - 1]) << i;
}

TEST_F(PlanSimTest, FilletsWhereArcsMeetLinesAreMeasuredAgainstTheProgrammedCurves) {
  // A barrel: two lines and two arcs meeting at 27 degree corners. Under G64 P0.05 each corner
  // gets a fillet that passes P from it, measured against the programmed line and arc; G61
  // stops at every corner.
  const std::string profile = "G1 X40 F3000\nG3 X40 Y20 I-5 J10\nG1 X0\nG3 X0 Y0 I5 J-10\nM2\n";
  const auto blended = simulate("G21 G90 G64 P0.05\n" + profile);
  const auto exact = simulate("G21 G90 G61\n" + profile);
  ASSERT_TRUE(blended.complete()) << (blended.error ? blended.error->to_string() : "");
  ASSERT_TRUE(exact.complete()) << (exact.error ? exact.error->to_string() : "");
  EXPECT_EQ(blended.moves, 4u);
  EXPECT_LE(blended.max_deviation, 0.05 + 1e-6);
  EXPECT_GE(blended.max_deviation, 0.03);
  EXPECT_LT(exact.max_deviation, 1e-6);
  EXPECT_LT(blended.cycle_time_s, exact.cycle_time_s - 0.05);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(blended.peak_velocity[axis], machine().axes[axis].max_velocity * 1.001);
    EXPECT_LE(blended.peak_acceleration[axis], machine().axes[axis].max_acceleration * 1.001);
  }
}

TEST_F(PlanSimTest, ASpiralFromRoundedCentreWordsIsFollowedOnItsPathToItsEnd) {
  motion::AxisPose last{};
  options_.on_sample = [&last](double, const motion::AxisPose& p, double) { last = p; };
  // I5.005: radius 5.005 at the start, 4.995 at the end; half a turn at 10 mm/s.
  const auto r = simulate("G21 G90 G61\nG0 X0 Y0\nG2 X10 Y0 I5.005 J0 F600\nM2\n");
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : "");
  EXPECT_LT(r.max_deviation, 1e-9);
  EXPECT_EQ(last[0], 10.0);
  EXPECT_EQ(last[1], 0.0);
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_LE(r.peak_velocity[axis], 200 * 1.001);
    EXPECT_LE(r.peak_acceleration[axis], 2000 * 1.001);
  }
  // Planned over half a turn of the larger radius, 5.005, with the 0.01 mm it closes in by:
  // 1.572 s at the feed, plus the ramps.
  EXPECT_NEAR(r.feed_bound_s, std::hypot(std::numbers::pi * 5.005, 0.01) / 10, 1e-12);
  EXPECT_GE(r.cycle_time_s, r.feed_bound_s);
  EXPECT_LE(r.cycle_time_s, r.feed_bound_s + 0.02);
}

TEST_F(PlanSimTest, StartsWhereTheMachineStands) {
  options_.start_machine = interp::Pose{50, 60, 0};
  const auto r = simulate("G21 G91\nG1 X10 F600\nM2\n");
  ASSERT_TRUE(r.complete());
  EXPECT_NEAR(r.feed_bound_s, 1.0, 1e-12);
  EXPECT_LT(r.max_deviation, 1e-9);
}

TEST_F(PlanSimTest, ErrorsNameTheFileAndTheLine) {
  auto r = simulate("G21 G90\nG0 X5\nG1 X10\nM2\n");
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->line, 3);
  EXPECT_NE(r.error->file.find("prog.ngc"), std::string::npos);
  r = simulate("G21 G90\nG0 X5\nG1 X320 F600\nM2\n");
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->line, 3);
  EXPECT_NE(r.error->message.find("X soft limits"), std::string::npos) << r.error->message;
}

TEST_F(PlanSimTest, BudgetsAndCancellingStopTheSimulationAndSaySo) {
  options_.max_machine_s = 0.5;
  auto r = simulate("G21 G90\nG1 X20 F600\nM2\n");
  ASSERT_TRUE(r.stopped);
  EXPECT_FALSE(r.complete());
  EXPECT_NE(r.stopped->message.find("longer than"), std::string::npos) << r.stopped->message;
  EXPECT_LE(r.cycle_time_s, 0.5 + 1.1);
  options_.max_machine_s = 0;
  std::atomic<bool> cancel{true};
  options_.cancel = &cancel;
  r = simulate("G21 G90\nG1 X20 F600\nM2\n");
  ASSERT_TRUE(r.stopped);
  EXPECT_NE(r.stopped->message.find("cancelled"), std::string::npos);
}

std::vector<std::string> lines_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

TEST_F(PlanSimTest, CncdCheckPlanPrintsFiguresJsonAndTheTrajectory) {
  const auto program = dir_.write("part.ngc", "G21 G90\nG0 X5 Y5\nG1 X15 F600\nM2\n");
  auto r = run_command({CNCD_CHECK_BINARY, "--plan", "--ini", ini_.string(), program.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("cycle time: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("feed-limited bound: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max path deviation: "), std::string::npos) << r.out;

  const auto csv = dir_.path() / "out.csv";
  r = run_command({CNCD_CHECK_BINARY, "--plan", "--json", "--trajectory", csv.string(), "--ini",
                   ini_.string(), program.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["complete"], true);
  EXPECT_EQ(report["moves"], 2);
  EXPECT_GT(report["cycle_time_s"].get<double>(), report["feed_bound_s"].get<double>());
  EXPECT_LE(report["axes"]["x"]["acceleration_ratio"].get<double>(), 1.001);
  const auto rows = lines_of(csv);
  ASSERT_EQ(rows.size(), report["cycles"].get<std::size_t>() + 1);
  EXPECT_EQ(rows.front(), "t,x,y,z,spindle,j0,j1,j2");
  char last[120];
  std::snprintf(last, sizeof last,
                "%.6f,15.000000,5.000000,0.000000,0.000000,15.000000,5.000000,0.000000",
                report["cycle_time_s"].get<double>());
  EXPECT_EQ(rows.back(), last);
  EXPECT_FALSE(std::filesystem::exists(csv.string() + ".tmp"));
}

TEST_F(PlanSimTest, CncdCheckPlanRefusesBadUseAndReportsProgramErrors) {
  const auto program = dir_.write("bad.ngc", "G21 G90\nG1 X10\nM2\n");
  EXPECT_EQ(run_command({CNCD_CHECK_BINARY, "--plan", program.string()}).exit_status, 2);
  EXPECT_EQ(run_command({CNCD_CHECK_BINARY, "--json", program.string()}).exit_status, 2);
  auto r = run_command({CNCD_CHECK_BINARY, "--plan", "--ini", ini_.string(), program.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find(program.string() + ":2:"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");  // it stopped before anything moved
  const auto good = dir_.write("good.ngc", "G0 X1\nM2\n");
  r = run_command({CNCD_CHECK_BINARY, "--plan", "--trajectory", "/nonexistent/dir/t.csv", "--ini",
                   ini_.string(), good.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("cannot write /nonexistent/dir/t.csv"), std::string::npos) << r.err;
}

// A move refused mid-program leaves moves planned that never start: the report's line start
// times list only the lines that started, each within the run (X30, planned but never handed
// to the servo loop, has no start time).
TEST_F(PlanSimTest, ARefusedMoveLeavesOnlyTheLinesThatStartedInTheReport) {
  const auto r = simulate("G21 G90\nG1 X10 F600\nG1 X20\nG1 X30\nG1 Y900\nM2\n");
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->line, 5);
  ASSERT_EQ(r.move_line, (std::vector<std::int32_t>{2, 3, 4}));
  ASSERT_LT(r.move_start_s.size(), r.move_line.size());
  std::vector<int> started;
  for (std::size_t i = 0; i < r.move_start_s.size(); ++i) {
    if (std::isfinite(r.move_start_s[i])) started.push_back(r.move_line[i]);
  }
  const auto report = nlohmann::json::parse(pipeline::plan_json(machine(), r));
  std::vector<int> lines;
  for (const auto& entry : report["line_start_s"]) {
    lines.push_back(entry[0].get<int>());
    EXPECT_GE(entry[1].get<double>(), 0.0);
    EXPECT_LE(entry[1].get<double>(), r.cycle_time_s);
  }
  EXPECT_EQ(lines, started);
  EXPECT_EQ(std::count(lines.begin(), lines.end(), 4), 0);
}

struct Sample {
  double t;
  motion::AxisPose at;
};

// Run from a line, read through the same runner as the daemon: the way to the line's start on
// the servo loop's own trajectory.
class FromLinePlan : public PlanSimTest {
 protected:
  void SetUp() override {
    PlanSimTest::SetUp();
    options_.start_machine = interp::Pose{};
    options_.on_sample = [this](double t, const motion::AxisPose& at, double) {
      samples_.push_back({t, at});
    };
  }
  pipeline::PlanSimResult simulate_from(const std::string& program, int from_line) {
    options_.from_line = from_line;
    samples_.clear();
    return simulate(program);
  }

  std::vector<Sample> samples_;
};

constexpr const char* kPart =
    "G21 G90\n"       // 1
    "G0 X30 Y20\n"    // 2
    "G1 Z-5 F1500\n"  // 3
    "G1 X40\n"        // 4
    "G1 Y30\n"        // 5
    "G0 Z10\n"        // 6
    "M2\n";           // 7

// From line 5: the lines before leave the tool at X40 Y20 Z-5. Z rises to [AXIS_Z] MAX_LIMIT
// (50) first, X and Y go over the start at that height, and Z comes down at F1500 (25 mm/s):
// every servo period of the way is checked.
TEST_F(FromLinePlan, ZRisesBeforeXAndYMoveAndComesDownAtTheFeed) {
  const double safe = pipeline::run_from_line_safe_z(*loaded_.config);
  ASSERT_EQ(safe, 50.0);
  const auto r = simulate_from(kPart, 5);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  ASSERT_GT(samples_.size(), 100u);
  bool reached_top = false, left_start = false, over_start = false;
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const auto& at = samples_[i].at;
    const bool at_origin = std::hypot(at[0], at[1]) < 1e-9;
    const bool over = std::hypot(at[0] - 40, at[1] - 20) < 1e-9;
    if (std::abs(at[2] - safe) < 1e-9) reached_top = true;
    if (!at_origin && !left_start) {
      left_start = true;
      EXPECT_TRUE(reached_top) << "X or Y moved at Z " << at[2] << ", t " << samples_[i].t;
    }
    if (!at_origin && !over_start && !over) {
      EXPECT_NEAR(at[2], safe, 1e-9) << "X" << at[0] << " Y" << at[1] << ", t " << samples_[i].t;
    }
    if (over && left_start) over_start = true;
    if (over_start && at[1] <= 20 + 1e-9 && i > 0) {
      // Coming down: no faster than the feed in force (25 mm/s), never below the start.
      const double speed = std::abs(at[2] - samples_[i - 1].at[2]) / r.period_s;
      EXPECT_LE(speed, 25.0 * (1 + 1e-6)) << "t " << samples_[i].t;
      EXPECT_GE(at[2], -5 - 1e-9);
    }
  }
  EXPECT_TRUE(left_start && over_start);
  // Then line 5 and line 6 as written.
  EXPECT_NEAR(samples_.back().at[0], 40, 1e-9);
  EXPECT_NEAR(samples_.back().at[1], 30, 1e-9);
  EXPECT_NEAR(samples_.back().at[2], 10, 1e-9);
}

// [CNCD] RUN_FROM_LINE_SAFE_Z sets the height; a machine already higher moves over where it is.
TEST_F(FromLinePlan, TheSafeHeightComesFromTheIniAndAHigherZStaysWhereItIs) {
  config::MachineConfig machine = *loaded_.config;
  machine.cncd.run_from_line_safe_z = 5.0;
  options_.from_line = 5;
  double top = -1e9;
  // The way ends at Y20, where line 5 starts its move to Y30.
  options_.on_sample = [&](double, const motion::AxisPose& at, double) {
    if (at[1] < 20 + 1e-9) top = std::max(top, at[2]);
  };
  auto r = pipeline::simulate_plan(machine, dir_.write("prog.ngc", kPart), options_);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  EXPECT_NEAR(top, 5.0, 1e-9);
  options_.start_machine = interp::Pose{0, 0, 30};
  options_.from_line = 5;
  bool moved_below_start = false;
  options_.on_sample = [&](double, const motion::AxisPose& at, double) {
    if (std::hypot(at[0] - 40, at[1] - 20) > 1e-9 && at[1] < 20 + 1e-9 && at[2] < 30 - 1e-9)
      moved_below_start = true;
  };
  r = pipeline::simulate_plan(machine, dir_.write("prog.ngc", kPart), options_);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  EXPECT_FALSE(moved_below_start);
}

// The way down needs a feed: a program with none in force before or on the line is refused at
// the line, before anything moves.
TEST_F(FromLinePlan, NoFeedForTheWayDownIsRefusedAtTheLine) {
  const auto r = simulate_from("G21 G90\nG0 X30 Y20 Z-5\nG0 X40\nG1 Y30 F600\nM2\n", 3);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->line, 3);
  EXPECT_NE(r.error->message.find("no feed is in force"), std::string::npos) << r.error->message;
  for (const auto& s : samples_)
    EXPECT_EQ(s.at, motion::AxisPose{});
}

}  // namespace
}  // namespace cncd::test
