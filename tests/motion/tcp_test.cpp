// Tool centre point control on the trunnion example (config/examples/sim_xyzac_trt.ini): the
// tool tip, found from every servo period's joint commands through the kinematics, stays on
// the programmed path within TCP_TOLERANCE, and no joint is ever asked for more than its
// MAX_VELOCITY or MAX_ACCELERATION, where the rotaries make the joints race included.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/kinematics.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::AxisPose;
using motion::Move;

constexpr int kA = 3, kC = 5;
constexpr double kTolerance = 0.005;  // the example's TCP_TOLERANCE

config::MachineConfig trunnion() {
  const auto result = config::load_machine_config(std::string(CNCD_SOURCE_DIR) +
                                                  "/config/examples/sim_xyzac_trt.ini");
  EXPECT_TRUE(result.ok()) << (result.problems.empty() ? "" : result.problems[0].to_string());
  return result.ok() ? *result.config : config::MachineConfig{};
}

Move tcp_move(Move::Kind kind, AxisPose end, double feed, bool tcp = true) {
  Move m;
  m.kind = kind;
  m.end = end;
  m.feed = feed;
  m.tcp = tcp;
  m.path_mode = Move::PathMode::blend;
  return m;
}

AxisPose pose(double x, double y, double z, double a, double c) {
  return {x, y, z, a, 0, c, 0, 0, 0};
}

// On and homed at the origin, then (TCP off, so the joints) at `at`, records cleared.
void ready_at(VirtualMachine& m, const AxisPose& at) {
  m.ready();
  m.queue(tcp_move(Move::Kind::traverse, at, 0, false));
  m.run_until_idle();
  m.cycles(2);
  m.clear_trajectory();
}

// The tool tip (part's frame) of every recorded period, for a tool `tool_length` long (the G43
// length; the example's TOOL_OFFSET is 0).
std::vector<AxisPose> tips(const VirtualMachine& m, double tool_length = 0) {
  const auto kins = motion::make_kinematics(m.config());
  std::vector<AxisPose> out;
  for (const AxisPose& joints : m.trajectory()) {
    AxisPose part{};
    kins->tcp_forward(joints, tool_length, part);
    out.push_back(part);
  }
  return out;
}

// Distance of `p`'s X Y Z from the line segment a-b.
double from_line(const AxisPose& p, const AxisPose& a, const AxisPose& b) {
  double ab = 0, ap = 0;
  for (int i = 0; i < 3; ++i) {
    ab += (b[i] - a[i]) * (b[i] - a[i]);
    ap += (p[i] - a[i]) * (b[i] - a[i]);
  }
  const double t = ab > 0 ? std::clamp(ap / ab, 0.0, 1.0) : 0.0;
  double d = 0;
  for (int i = 0; i < 3; ++i) {
    const double e = p[i] - (a[i] + t * (b[i] - a[i]));
    d += e * e;
  }
  return std::sqrt(d);
}

TEST(TcpTest, TiltingAWithXyzHeldKeepsTheToolTipOnItsPoint) {
  VirtualMachine m(trunnion());
  const AxisPose point = pose(30, 40, 20, 0, 0);
  ready_at(m, point);  // A = C = 0: the part's frame is the machine's
  m.queue(tcp_move(Move::Kind::feed, pose(30, 40, 20, -90, 0), 30));  // G1 A-90 F1800
  m.run_until_idle();
  double worst = 0;
  for (const AxisPose& tip : tips(m))
    worst = std::max(worst, from_line(tip, point, point));
  std::printf("G1 A-90 under TCP: the tip within %.6f mm of its point\n", worst);
  EXPECT_LE(worst, kTolerance);
  // The table did tilt, and the joints carried the point around the A axis (Y 20, Z 10):
  // 20 mm behind and 10 above it, turned -90 degrees, it is 10 mm behind and 20 below.
  const auto& end = m.trajectory().back();
  EXPECT_NEAR(end[kA], -90, 1e-9);
  EXPECT_NEAR(end[0], 30, 1e-9);
  EXPECT_NEAR(end[1], 30, 1e-9);
  EXPECT_NEAR(end[2], -10, 1e-9);
  expect_joints_within_limits(m, "G1 A-90 under TCP");
}

// What status publishes: the tip in the part's frame from the commanded and the actual joints
// every period, and the TCP state of the segment under way, kept once it is done.
TEST(TcpTest, TheStatusShowsTheTipAndWhetherThePathRunsUnderTcp) {
  VirtualMachine m(trunnion());
  const AxisPose point = pose(30, 40, 20, 0, 0);
  ready_at(m, point);
  motion::Status s = m.status();
  EXPECT_TRUE(s.has_tcp);
  EXPECT_FALSE(s.tcp);
  EXPECT_EQ(s.tip_commanded, s.commanded);  // every rotary at 0
  m.queue(tcp_move(Move::Kind::feed, pose(30, 40, 20, -90, 0), 30));
  m.flush();
  double worst = 0;
  int periods = 0;
  for (int k = 0; k < 100000; ++k) {
    m.cycles(1);
    s = m.status();
    if (s.motion == motion::MotionState::idle && s.queued == 0) break;
    ++periods;
    EXPECT_TRUE(s.tcp) << "period " << k;
    worst = std::max(
        {worst, from_line(s.tip_commanded, point, point), from_line(s.tip_actual, point, point)});
  }
  std::printf("status under TCP, %d periods: the tip within %.6f mm of its point\n", periods,
              worst);
  EXPECT_GT(periods, 1000);
  EXPECT_LE(worst, kTolerance);
  EXPECT_TRUE(s.tcp);  // the last segment's, at rest
  EXPECT_NEAR(s.commanded[1], 30, 1e-9);
  EXPECT_NEAR(s.tip_commanded[1], 40, 1e-9);
  EXPECT_NEAR(s.tip_commanded[kA], -90, 1e-9);
  m.queue(tcp_move(Move::Kind::feed, pose(30, 30, 10, -90, 0), 30, false));
  m.run_until_idle();
  EXPECT_FALSE(m.status().tcp);
}

TEST(TcpTest, WithTcpOffTheSameMoveTurnsTheTableAlone) {
  VirtualMachine m(trunnion());
  ready_at(m, pose(30, 40, 20, 0, 0));
  m.queue(tcp_move(Move::Kind::feed, pose(30, 40, 20, -90, 0), 30, false));
  m.run_until_idle();
  ASSERT_GT(m.trajectory().size(), 100u);
  for (const AxisPose& joints : m.trajectory()) {
    EXPECT_EQ(joints[0], 30);
    EXPECT_EQ(joints[1], 40);
    EXPECT_EQ(joints[2], 20);
  }
  EXPECT_NEAR(m.trajectory().back()[kA], -90, 1e-9);
}

TEST(TcpTest, AStraightLineWhileAAndCTurnStaysWithinTheTolerance) {
  VirtualMachine m(trunnion());
  const AxisPose from = pose(-20, -10, 0, 0, 0);
  const AxisPose to = pose(30, 20, 10, -30, 60);
  ready_at(m, from);
  m.queue(tcp_move(Move::Kind::feed, to, 10));
  m.run_until_idle();
  const auto path = tips(m);
  double worst = 0;
  for (const AxisPose& tip : path)
    worst = std::max(worst, from_line(tip, from, to));
  std::printf("line under TCP with A and C turning: the tip within %.6f mm of the line\n", worst);
  EXPECT_LE(worst, kTolerance + 1e-9);
  EXPECT_LE(from_line(path.back(), to, to), 1e-9);  // and it ends where it should
  EXPECT_NEAR(path.back()[kC], 60, 1e-9);
  expect_joints_within_limits(m, "line under TCP with A and C turning");
}

TEST(TcpTest, ALargeCSwingAtANearZeroKeepsEveryJointWithinItsLimits) {
  // Near the C axis's singularity (A 0: C alone no longer changes the tool's direction) a
  // short line asks C for half a turn: the X and Y joints must carry the point 60 mm from
  // the C axis around it while the tip hardly moves. The feed drops; no joint's limit gives.
  VirtualMachine m(trunnion());
  const AxisPose from = pose(60, 0, 0, -0.01, 0);
  ready_at(m, from);
  m.queue(tcp_move(Move::Kind::feed, pose(61, 0, 0, 0, 180), 50));
  m.queue(tcp_move(Move::Kind::traverse, pose(0, 61, 0, 0, 90), 0));
  m.run_until_idle();
  const Peaks p = expect_joints_within_limits(m, "C swing of 180 degrees at A 0");
  EXPECT_GT(p.velocity, 0.9);  // a joint's limit, not the feed, sets the pace
  // Half a turn at 60 mm takes X and Y 188 mm at 20 mm/s at most: far longer than the 1 mm
  // line at 50 mm/s or C's own 6 s.
  EXPECT_GT(static_cast<double>(m.trajectory().size()) * m.period_s(), 9.0);
  const auto path = tips(m);
  EXPECT_LE(from_line(path.back(), pose(0, 61, 0, 0, 90), pose(0, 61, 0, 0, 90)), 1e-9);
}

TEST(TcpTest, EachMoveTurnsTheTipOfTheToolLengthItCarries) {
  // G43 with a 50 mm tool: the program's tip at (30, 40, -30) puts the controlled point at
  // Z 20; tilting A keeps that tool's tip, 50 mm below the controlled point, where it is.
  VirtualMachine m(trunnion());
  const AxisPose point = pose(30, 40, 20, 0, 0);
  ready_at(m, point);
  Move tilt = tcp_move(Move::Kind::feed, pose(30, 40, 20, -90, 0), 30);
  tilt.tool_length = 50;
  m.queue(tilt);
  m.run_until_idle();
  double worst = 0;
  for (const AxisPose& tip : tips(m, 50))
    worst = std::max(worst, from_line(tip, point, point));
  std::printf("G43 50 mm, G1 A-90 under TCP: the tip within %.6f mm of its point\n", worst);
  EXPECT_LE(worst, kTolerance);
  // The tip 20 mm behind the A axis (Y 20, Z 10) and 40 below it, turned -90 degrees: 40 mm
  // before it and 20 below, the controlled point 50 above that.
  const AxisPose end = m.trajectory().back();
  EXPECT_NEAR(end[0], 30, 1e-9);
  EXPECT_NEAR(end[1], -20, 1e-9);
  EXPECT_NEAR(end[2], 40, 1e-9);
  // A tool of another length would have its tip elsewhere: the length is no detail.
  EXPECT_GT(from_line(tips(m, 0).back(), point, point), 50);
  expect_joints_within_limits(m, "G1 A-90 under TCP with a 50 mm tool");
}

TEST(TcpTest, AToolLengthChangeAtATiltOfZeroMovesNoJoint) {
  // C turns with a 30 mm tool, then A tilts with a 50 mm one: at A 0 the length moves no
  // joint, so the two moves meet without a jump and the new tool's tip is held.
  VirtualMachine m(trunnion());
  const AxisPose point = pose(30, 40, 20, 0, 0);
  ready_at(m, point);
  Move turn = tcp_move(Move::Kind::feed, pose(30, 40, 20, 0, 90), 30);
  turn.tool_length = 30;
  Move tilt = tcp_move(Move::Kind::feed, pose(30, 40, 20, -90, 90), 30);
  tilt.tool_length = 50;
  m.queue(turn);
  m.queue(tilt);
  m.run_until_idle();
  double worst = 0;
  for (const AxisPose& tip : tips(m, 50))  // at A 0 any length gives the same tip
    worst = std::max(worst, from_line(tip, point, point));
  std::printf("C 90 with 30 mm, then A -90 with 50 mm: the tip within %.6f mm\n", worst);
  EXPECT_LE(worst, kTolerance);
  // C 90 takes the tip (30, 40, -30) to (-40, 30, -30); A -90 swings it about the A axis to
  // (-40, -20, 0), the controlled point 50 mm above.
  const AxisPose end = m.trajectory().back();
  EXPECT_NEAR(end[0], -40, 1e-9);
  EXPECT_NEAR(end[1], -20, 1e-9);
  EXPECT_NEAR(end[2], 50, 1e-9);
  expect_joints_within_limits(m, "a tool length change at A 0 under TCP");
}

TEST(TcpTest, AToolLengthChangeWithTheTableTiltedIsRefused) {
  // Tilted, the new length puts the tip elsewhere in the machine: the joints would jump.
  const config::MachineConfig config = trunnion();
  motion::Planner planner(config);
  planner.reset(pose(30, 40, 20, 0, 0));
  std::string error;
  Move move = tcp_move(Move::Kind::feed, pose(30, 40, 20, -30, 0), 30);
  move.tool_length = 50;
  ASSERT_TRUE(planner.push(move, true, error)) << error;
  move.end = pose(31, 40, 20, -30, 0);
  move.tool_length = 30;
  EXPECT_FALSE(planner.push(move, true, error));
  EXPECT_EQ(error.rfind("the tool length changes from 50.0000 to 30.0000 under TCP", 0), 0u)
      << error;
  move.tool_length = 50;  // nothing changed: the same tool goes on
  EXPECT_TRUE(planner.push(move, true, error)) << error;
  move.end = pose(31, 40, 20, 0, 45);
  EXPECT_TRUE(planner.push(move, true, error)) << error;
  // Level again, C anywhere: the change moves no joint.
  move.end = pose(32, 40, 20, 0, 45);
  move.tool_length = 30;
  EXPECT_TRUE(planner.push(move, true, error)) << error;
}

TEST(TcpTest, AJointPastItsLimitIsRefusedThoughTheTipStaysInTheBox) {
  // The tip at X 120, well within the X axis's -200 .. 200, and C turning: the table carries
  // that point around the C axis, to Y 120 sin C, past the Y joint's 100 from C 56.4 on.
  const config::MachineConfig config = trunnion();
  motion::Planner planner(config);
  planner.reset(pose(0, 0, 0, 0, 0));
  std::string error;
  ASSERT_TRUE(planner.push(tcp_move(Move::Kind::feed, pose(120, 0, 0, 0, 0), 10), true, error))
      << error;
  EXPECT_TRUE(planner.push(tcp_move(Move::Kind::feed, pose(120, 0, 0, 0, 50), 10), true, error))
      << error;  // Y 120 sin 50 = 91.9
  EXPECT_FALSE(planner.push(tcp_move(Move::Kind::feed, pose(120, 0, 0, 0, 90), 10), true, error));
  EXPECT_EQ(error.substr(0, 31), "the move takes joint 1 (Y) to 1") << error;
  EXPECT_NE(error.find("outside its soft limits [-100.0000, 100.0000]"), std::string::npos)
      << error;
  // With TCP off the same move only turns C: accepted.
  EXPECT_TRUE(
      planner.push(tcp_move(Move::Kind::feed, pose(120, 0, 0, 0, 90), 10, false), true, error))
      << error;
}

TEST(TcpTest, ATapWithTheRotariesStillIsOneJointLineOfTheSameLength) {
  // At A-30 the tip's line down the part's Z is a line in joint space along the tilted Z,
  // as long, in step with the spindle at the same distance per revolution; turning C in step
  // with the spindle is refused.
  const config::MachineConfig config = trunnion();
  const auto kins = motion::make_kinematics(config);
  motion::Planner planner(config);
  AxisPose start{};
  kins->tcp_inverse(pose(10, 5, 5, -30, 0), 0.0, start);
  planner.reset(start);
  Move tap = tcp_move(Move::Kind::feed, pose(10, 5, -10, -30, 0), 12.5);
  tap.path_mode = Move::PathMode::exact_stop;
  tap.spindle_sync = motion::SpindleSync::tap;
  tap.per_rev = 1.25;
  std::string error;
  ASSERT_TRUE(planner.push(tap, true, error)) << error;
  planner.flush();
  ASSERT_EQ(planner.output().size(), 1u);
  const motion::Segment& line = planner.output().front();
  AxisPose bottom{};
  kins->tcp_inverse(pose(10, 5, -10, -30, 0), 0.0, bottom);
  for (int i = 0; i < motion::kAxes; ++i) {
    EXPECT_NEAR(line.start[i], start[i], 1e-12) << i;
    EXPECT_NEAR(line.end[i], bottom[i], 1e-12) << i;
  }
  EXPECT_NEAR(line.length, 15, 1e-12);
  EXPECT_NEAR(std::hypot(line.end[1] - line.start[1], line.end[2] - line.start[2]), 15, 1e-12);
  EXPECT_NEAR(line.end[1] - line.start[1], -15 * std::sin(30 * M_PI / 180), 1e-12);
  EXPECT_EQ(line.spindle_sync, motion::SpindleSync::tap);
  EXPECT_EQ(line.per_rev, 1.25);
  Move turning = tap;
  turning.end = pose(10, 5, -10, -30, 20);
  EXPECT_FALSE(planner.push(turning, true, error));
  EXPECT_NE(error.find("turns C under TCP (M428)"), std::string::npos) << error;
}

}  // namespace
}  // namespace cncd::test
