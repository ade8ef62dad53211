// Rigid tapping under TCP on the trunnion (config/examples/sim_xyzac_trt.ini), in the plan
// simulation: with the table tilted 30 degrees about A and the rotaries still, G33.1, the
// Numeryx g74 (examples/numeryx/rigid_tap.ngc) and a rigid G84 cycle tap along the part's Z,
// which the tilted table turns: the tool tip (the joints through the forward kinematics) stays
// on the hole's axis and on the helix the spindle's position gives, reaches the bottom and
// comes back to where it started. A move in step with the spindle that turns a rotary, a probing
// move and a thread too fast for a joint are refused under TCP at their line, before anything
// runs.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "tcp_plan_fixture.hpp"

namespace cncd::test {
namespace {

constexpr double kTilt = 30;  // degrees about A

const std::string kHead = "G21 G90 G94 G17\nG0 X0 Y0 Z30 A0 C0\nM428\nG0 A30\n";
const std::string kTail = "G90 G0 X0 Y0\nG0 Z30\nG0 A0\nM429\nM2\n";

// A tap found in a run: the samples below the height it starts at, at one XY of the tip.
struct Tap {
  double x = 0, y = 0;
  double top = 0, bottom = 0;
  double off_axis = 0;                 // the tip from the hole's axis (part frame)
  double helix_error = 0;              // the tip's Z from the helix the spindle gives
  std::size_t deepest = 0, after = 0;  // sample indexes: the bottom and the first one out
};

class TcpTap : public TcpPlan {
 protected:
  // Runs of samples whose tip goes below `top`, with their helix error: z_ideal = top - pitch
  // x (revolutions - the spindle's position at rest before the run).
  std::vector<Tap> taps(const TcpRun& run, double top, double pitch) const {
    std::vector<Tap> found;
    const auto& s = run.samples;
    for (std::size_t k = 1; k < s.size(); ++k) {
      if (!(s[k].tip[2] < top - 1e-9) || s[k - 1].tip[2] < top - 1e-9) continue;
      Tap tap;
      tap.x = s[k - 1].tip[0];
      tap.y = s[k - 1].tip[1];
      tap.top = s[k - 1].tip[2];
      tap.bottom = s[k].tip[2];
      tap.deepest = k;
      const double locked = s[k - 1].revolutions;
      std::size_t j = k;
      for (; j < s.size() && s[j].tip[2] < top - 1e-9; ++j) {
        const motion::AxisPose& p = s[j].tip;
        tap.off_axis = std::max(tap.off_axis, std::hypot(p[0] - tap.x, p[1] - tap.y));
        if (p[2] < tap.bottom) tap.deepest = j;
        tap.bottom = std::min(tap.bottom, p[2]);
        const double ideal = top - pitch * (s[j].revolutions - locked);
        tap.helix_error = std::max(tap.helix_error, std::abs(p[2] - ideal));
      }
      tap.after = j;
      found.push_back(tap);
      k = j;
    }
    return found;
  }

  void expect_tap(const TcpRun& run, const Tap& tap, double x, double y, double top, double bottom,
                  double pitch) {
    SCOPED_TRACE("tap at X" + std::to_string(x) + " Y" + std::to_string(y));
    EXPECT_NEAR(tap.x, x, 1e-9);
    EXPECT_NEAR(tap.y, y, 1e-9);
    EXPECT_NEAR(tap.top, top, 1e-9);
    EXPECT_LE(tap.off_axis, 1e-6);
    // As out of TCP (tests/daemon/sync_plan_test.cpp): the spindle turns the tap back.
    EXPECT_NEAR(tap.bottom, bottom, 0.002);
    EXPECT_LE(tap.helix_error, pitch * 0.02);
    // The joints there: the bottom's inverse kinematics, not the machine's own X Y Z.
    const motion::AxisPose at = run.samples[tap.deepest].joints;
    EXPECT_LE(pose_distance(at, joints_at(x, y, tap.bottom, kTilt)), 1e-9);
    EXPECT_GT(pose_distance(at, {x, y, tap.bottom, kTilt, 0, 0, 0, 0, 0}), 1.0);
    // Back where it started.
    ASSERT_LT(tap.after, run.samples.size());
    EXPECT_NEAR(run.samples[tap.after].tip[2], top, 1e-9);
    worst_off_axis_ = std::max(worst_off_axis_, tap.off_axis);
    worst_helix_ = std::max(worst_helix_, tap.helix_error);
    worst_bottom_ = std::max(worst_bottom_, std::abs(tap.bottom - bottom));
  }

  void report(const char* name, const TcpRun& run) const {
    std::printf("%s: cycle time %.3f s; off axis %.2g mm, helix %.2g mm, bottom %.2g mm\n", name,
                run.result.cycle_time_s, worst_off_axis_, worst_helix_, worst_bottom_);
  }

  // The machine with [RS274NGC] RIGID_TAPPING = 1: G84 taps rigidly.
  void tap_rigidly() {
    std::string ini = slurp(ini_);
    const std::string section = "[RS274NGC]\n";
    ASSERT_NE(ini.find(section), std::string::npos);
    ini.replace(ini.find(section), section.size(), section + "RIGID_TAPPING = 1\n");
    std::ofstream(ini_) << ini;
    loaded_ = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded_.ok());
    ASSERT_TRUE(loaded_.config->rigid_tapping);
  }

  double worst_off_axis_ = 0, worst_helix_ = 0, worst_bottom_ = 0;
};

TEST_F(TcpTap, G33_1TapsAlongTheTiltedZ) {
  const auto run =
      simulate("tap.ngc", kHead + "G0 X10 Y10 Z5\nM3 S600\nG33.1 Z-10 K1.25\n" + kTail);
  const auto found = taps(run, 5, 1.25);
  ASSERT_EQ(found.size(), 1u);
  expect_tap(run, found[0], 10, 10, 5, -10, 1.25);
  report("G33.1", run);
}

TEST_F(TcpTap, NumeryxG74TapsEveryHoleAlongTheTiltedZ) {
  // R1 = R + 1 mm = 3, to Z-14, f1250: 1.25 mm a revolution.
  std::ifstream in(std::string(CNCD_SOURCE_DIR) + "/examples/numeryx/rigid_tap.ngc");
  std::string body, line;
  while (std::getline(in, line)) {
    if (line.find("(dialect") == 0 || line == "m2") continue;
    body += line + "\n";
  }
  std::string text = kHead + body + kTail;
  std::transform(text.begin(), text.end(), text.begin(), ::tolower);
  const auto run = simulate("rigid_tap.ngc", "(dialect numeryx)\n" + text);
  const auto found = taps(run, 3, 1.25);
  ASSERT_EQ(found.size(), 3u);
  for (int n = 0; n < 3; ++n)
    expect_tap(run, found[static_cast<std::size_t>(n)], 20.0 + 20.0 * n, 20, 3, -14, 1.25);
  report("g74", run);
}

TEST_F(TcpTap, RigidG84CycleTapsAlongTheTiltedZ) {
  tap_rigidly();
  // G94: the pitch is F/S = 750 / 600 = 1.25 mm; R2, bottom -6, G98 back to Z10.
  const auto run =
      simulate("g84.ngc", kHead +
                              "G0 X0 Y0 Z10\nM3 S600\nG98 G84 X10 Y5 Z-6 R2 F750\nX25 Y-5\n"
                              "G80\n" +
                              kTail);
  const auto found = taps(run, 2, 1.25);
  ASSERT_EQ(found.size(), 2u);
  expect_tap(run, found[0], 10, 5, 2, -6, 1.25);
  expect_tap(run, found[1], 25, -5, 2, -6, 1.25);
  report("rigid G84", run);
}

// What TCP cannot do is refused at its line by the program's check and the plan alike.
TEST_F(TcpTap, TurningARotaryInStepWithTheSpindleAndProbingAreRefusedAtTheirLine) {
  struct Case {
    std::string name, move, message;
  };
  const std::vector<Case> cases{
      {"thread_a.ngc", "G33 Z-5 A20 K1.25",
       "a move in step with the spindle (G33, G33.1, rigid tapping) turns A under TCP "
       "(M428): under TCP it runs with the rotary axes held still"},
      {"thread_c.ngc", "G33 Z-5 C20 K1.25", "turns C under TCP (M428)"},
      {"probe.ngc", "G38.2 Z-5 F100",
       "probing (G38.n) is not available under TCP (M428): the probe's trip point is known "
       "in the machine's frame only; M429 first"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string text = kHead + "S500 M3\nG0 X5 Y5 Z5\n" + c.move + "\n" + kTail;
    const auto program = dir_.write(c.name, text);
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(*loaded_.config);
    options.start_machine = interp::Pose{};
    const auto r = pipeline::simulate_plan(*loaded_.config, program, options);
    ASSERT_TRUE(r.error.has_value());
    EXPECT_NE(r.error->to_string().find(c.name + ":7: "), std::string::npos)
        << r.error->to_string();
    EXPECT_NE(r.error->to_string().find(c.message), std::string::npos) << r.error->to_string();
    const auto checked = run_command({CNCD_CHECK_BINARY, "--ini", ini_.string(), program.string()});
    EXPECT_EQ(checked.exit_status, 1);
    EXPECT_NE(checked.err.find(program.string() + ":7: "), std::string::npos) << checked.err;
    EXPECT_NE(checked.err.find(c.message), std::string::npos) << checked.err;
  }
  // Out of TCP the same thread runs: A turns with it, as LinuxCNC's G33 allows.
  const auto plain =
      dir_.write("plain.ngc", "G21 G90\nG0 X5 Y5 Z5 A0 C0\nS500 M3\nG33 Z-5 A20 K1.25\nM2\n");
  pipeline::PlanSimOptions options;
  options.interp = pipeline::interpreter_options(*loaded_.config);
  options.start_machine = interp::Pose{};
  const auto r = pipeline::simulate_plan(*loaded_.config, plain, options);
  EXPECT_TRUE(r.complete()) << (r.error ? r.error->to_string() : "");
}

// G33's check that the axes keep up with the thread takes the joints' speeds under TCP: at A45
// a thread down the part's Y-Z diagonal at 25 mm/s moves each of the tip's Y and Z at 17.7 mm/s,
// within their 20, but the joints along Z alone, at 25.
TEST_F(TcpTap, AThreadTooFastForAJointIsRefusedAtItsLine) {
  const auto program = dir_.write("fast.ngc",
                                  "G21 G90 G94 G17\nG0 X0 Y0 Z30 A0 C0\nM428\nG0 A45\n"
                                  "G0 X0 Y0 Z10\nS1000 M3\nG33 X0 Y-10 Z0 K1.5\n" +
                                      kTail);
  const auto checked = run_command({CNCD_CHECK_BINARY, "--ini", ini_.string(), program.string()});
  EXPECT_EQ(checked.exit_status, 1);
  EXPECT_NE(checked.err.find(program.string() +
                             ":7: G33 at S1000 with 1.5 mm per revolution needs Z at 25 mm/s; "
                             "[AXIS_Z] MAX_VELOCITY is 20 mm/s"),
            std::string::npos)
      << checked.err;
}

}  // namespace
}  // namespace cncd::test
