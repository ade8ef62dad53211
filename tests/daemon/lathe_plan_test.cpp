// The sim lathe's turning example in the plan simulation: its cycle time counts the spindle's
// ramps (the program waits at each M3 and each G96 speed change until the spindle is at speed),
// and a spindle too slow to reach its speed within [SPINDLE_0] AT_SPEED_TIMEOUT ends the plan
// with the machine's error at the line that waited, as the daemon ends the program there.
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class LathePlan : public ::testing::Test {
 protected:
  // The sim lathe with its spindle ramping at `rpm_per_s`.
  std::filesystem::path lathe(double rpm_per_s) {
    const auto dir = dir_.path() / std::to_string(static_cast<int>(rpm_per_s));
    std::filesystem::create_directories(dir);
    const auto ini = copy_example_machine(dir, "sim_lathe");
    std::stringstream text;
    text << std::ifstream(ini).rdbuf();
    std::string body = text.str();
    const std::string ramp = "\nACCELERATION = 1500\nAT_SPEED";
    const auto at = body.find(ramp);
    EXPECT_NE(at, std::string::npos);
    if (at == std::string::npos) return ini;
    body.replace(at, ramp.size(),
                 "\nACCELERATION = " + std::to_string(static_cast<int>(rpm_per_s)) + "\nAT_SPEED");
    std::ofstream(ini) << body;
    return ini;
  }

  pipeline::PlanSimResult simulate(const std::filesystem::path& ini) {
    const auto loaded = config::load_machine_config(ini);
    EXPECT_TRUE(loaded.ok());
    if (!loaded.ok()) return {};
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(*loaded.config);
    // The tool table the machine starts from (as cncd-check --ini reads it).
    options.interp.tool_table =
        config::state_file_to_read(loaded.config->tool_table, loaded.config->tool_table_seed);
    return pipeline::simulate_plan(*loaded.config, example_, options);
  }

  TempDir dir_;
  const std::filesystem::path example_ =
      std::filesystem::path(CNCD_SOURCE_DIR) / "examples/lathe_turning.ngc";
};

TEST_F(LathePlan, TheTurningExamplesTimeCountsTheSpindlesRamps) {
  const auto quick = simulate(lathe(1500));
  ASSERT_TRUE(quick.complete()) << (quick.error ? quick.error->to_string() : "stopped");
  const auto slow = simulate(lathe(300));
  ASSERT_TRUE(slow.complete()) << (slow.error ? slow.error->to_string() : "stopped");
  // The first spin-up alone: G96 S120 at a radius of 11 mm is 1736 rpm, 1.16 s at 1500 rpm/s
  // and 5.79 s at 300; the later speed changes add more.
  EXPECT_GT(slow.cycle_time_s - quick.cycle_time_s, 4.6)
      << quick.cycle_time_s << " s against " << slow.cycle_time_s << " s";
  EXPECT_LT(quick.max_deviation, 0.02);
  EXPECT_LT(slow.max_deviation, 0.02);
}

TEST_F(LathePlan, ASpindleThatCannotReachItsSpeedInTimeEndsThePlanAtItsLine) {
  // 1736 rpm at 50 rpm/s takes 35 s; the machine gives up after AT_SPEED_TIMEOUT = 10 s.
  const auto ini = lathe(50);
  const auto r = simulate(ini);
  ASSERT_TRUE(r.error.has_value()) << "the plan ran to its end";
  EXPECT_EQ(r.error->line, 11) << r.error->to_string();
  EXPECT_NE(r.error->message.find("AT_SPEED_TIMEOUT"), std::string::npos) << r.error->message;

  const auto run =
      run_command({CNCD_CHECK_BINARY, "--plan", "--ini", ini.string(), example_.string()});
  EXPECT_EQ(run.exit_status, 1) << run.out;
  EXPECT_NE(run.err.find("lathe_turning.ngc:11: spindle 0 did not reach"), std::string::npos)
      << run.err;
  EXPECT_NE(run.out.find("(incomplete)"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace cncd::test
