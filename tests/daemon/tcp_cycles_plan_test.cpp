// Canned cycles under TCP on the trunnion (config/examples/sim_xyzac_trt.ini), in the plan
// simulation: the seed G81 examples (tests/golden/seed_*: the LinuxCNC and PathPilot manuals'
// two examples and the G80 section's eight holes), the Numeryx note's cycle in one block
// (examples/numeryx/one_block.ngc), a G83 peck with G99, the other cycles (G87 and G88 for
// their path alone), each run with the table tilted 30 degrees about A under M428, and
// examples/xyzac_trt_cycles.ngc. The programmed X Y Z are the tool tip in the part's frame, so
// every cycle drills along the part's Z, which the tilted table turns. From every servo
// period's joints through the forward kinematics: each hole's bottom (and each peck's) is the
// programmed point in the part's frame, the joints there its inverse kinematics, within 1 um;
// in the hole the tip stays on its axis within 1 um; it feeds from the R plane (R1 in the
// Numeryx dialect), where the path stops as at the bottom (exact path, as out of TCP), and
// leaves at the retract level G98/G99 give; and every period's tip lies on the programmed move
// under way.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "tcp_plan_fixture.hpp"

namespace cncd::test {
namespace {

constexpr double kTilt = 30;      // degrees about A
constexpr double kMicron = 1e-3;  // mm

struct Hole {
  double x, y;
  double r;                     // where the feed starts
  double bottom;                // the deepest point
  double top;                   // the highest point on its axis (where the tip arrives or leaves)
  double leave;                 // where the tip leaves the axis
  double feed;                  // mm/s; 0: not checked (pecks rapid down inside the hole)
  std::vector<double> pecks{};  // the depths the tip turns back up at, in order; {} = bottom
};

// A program's lines without its end (M2, M30) and dialect line.
std::string body_of(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    std::string lower = line;
    std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
    if (lower.find("m2 ") != std::string::npos || lower.ends_with("m2") ||
        lower.find("m30") != std::string::npos || lower.find("(dialect") == 0)
      continue;
    out += line + "\n";
  }
  return out;
}

// Up at the origin, TCP on, the table tilted; the program; away from the last hole, the table
// level, TCP off.
std::string tilted(const std::string& body, bool numeryx = false) {
  const std::string head = "G21 G90 G94 G17 G64\nG0 X0 Y0 Z30 A0 C0\nM428\nG0 A30\n";
  const std::string tail = "G80\nG90 G0 X0 Y0\nG0 Z30\nG0 A0\nM429\nM2\n";
  std::string text = head + body + tail;
  if (!numeryx) return text;
  std::transform(text.begin(), text.end(), text.begin(), ::tolower);
  return "(dialect numeryx)\n" + text;
}

std::string golden(const std::string& name) {
  return slurp(std::string(CNCD_SOURCE_DIR) + "/tests/golden/" + name + "/program.ngc");
}

struct Figures {
  double bottom = 0;   // tip from the programmed bottom (and pecks), part frame
  double joints = 0;   // joints there from its inverse kinematics
  double on_axis = 0;  // tip from the hole's axis while in the hole
  double on_path = 0;  // tip from the programmed move, rotaries held
  double turning = 0;  // the same while a rotary turns (TCP_TOLERANCE applies)
};

class TcpCycles : public TcpPlan {
 protected:
  // Every sample on the programmed move under way: within 1 um where the rotaries stand still
  // (each move is one straight joint-space line, the tip's map a rotation), within
  // TCP_TOLERANCE where they turn (the move is cut into pieces).
  void expect_on_path(const TcpRun& run, Figures& f) {
    ASSERT_EQ(run.moves.size(), run.move_start_s.size());
    std::size_t m = 0;
    for (const TcpSample& s : run.samples) {
      while (m + 1 < run.moves.size() && run.move_start_s[m + 1] < s.t)
        ++m;
      const motion::Segment& move = run.moves[m];
      ASSERT_NE(move.kind, motion::Segment::Kind::arc);
      const bool turns = move.start[3] != move.end[3] || move.start[5] != move.end[5];
      double& worst = turns ? f.turning : f.on_path;
      worst = std::max(worst, from_line(s.tip, move.start, move.end));
    }
    EXPECT_LE(f.on_path, kMicron);
    EXPECT_LE(f.turning, loaded_.config->table_rotary.tcp_tolerance);
  }

  static double from_line(const motion::AxisPose& p, const motion::AxisPose& a,
                          const motion::AxisPose& b) {
    double ab = 0, ap = 0;
    for (int i = 0; i < 3; ++i) {
      ab += (b[i] - a[i]) * (b[i] - a[i]);
      ap += (p[i] - a[i]) * (b[i] - a[i]);
    }
    const double t = ab > 0 ? std::clamp(ap / ab, 0.0, 1.0) : 0.0;
    motion::AxisPose q = a;
    for (int i = 0; i < 3; ++i)
      q[i] = a[i] + t * (b[i] - a[i]);
    return xyz_distance(p, q);
  }

  void expect_hole(const TcpRun& run, const Hole& h, Figures& f) {
    SCOPED_TRACE("hole at X" + std::to_string(h.x) + " Y" + std::to_string(h.y));
    // The samples on the hole's axis, in order (the tip comes there once), and those in the
    // hole (below R) near it, which must be on it.
    std::vector<const TcpSample*> at;
    for (const TcpSample& s : run.samples) {
      const double off = std::hypot(s.tip[0] - h.x, s.tip[1] - h.y);
      if (off < 0.25 && s.tip[2] < h.r - 1e-9) f.on_axis = std::max(f.on_axis, off);
      if (off < 1e-6) at.push_back(&s);
    }
    ASSERT_GT(at.size(), 10u);
    double low = 1e9, high = -1e9, below_r = 0, above_r = 0;
    const TcpSample* deepest = at.front();
    std::vector<double> turns;  // where the tip turns from down to up
    double previous_z = at.front()->tip[2];
    bool down = false;
    for (std::size_t k = 0; k < at.size(); ++k) {
      const TcpSample& s = *at[k];
      if (s.tip[2] < low) deepest = &s;
      low = std::min(low, s.tip[2]);
      high = std::max(high, s.tip[2]);
      if (k > 0) {
        const double dz = s.tip[2] - at[k - 1]->tip[2];
        const double speed = -dz / (s.t - at[k - 1]->t);
        if (dz < 0 && at[k - 1]->tip[2] < h.r - 1e-6) below_r = std::max(below_r, speed);
        if (dz < 0 && s.tip[2] > h.r + 1e-6) above_r = std::max(above_r, speed);
      }
      if (std::abs(s.tip[2] - previous_z) > 1e-12) {
        if (down && s.tip[2] > previous_z) turns.push_back(previous_z);
        down = s.tip[2] < previous_z;
        previous_z = s.tip[2];
      }
    }
    EXPECT_NEAR(low, h.bottom, kMicron);
    EXPECT_NEAR(high, h.top, kMicron);
    EXPECT_NEAR(at.back()->tip[2], h.leave, kMicron);
    // Rapid down to R, at most the feed below it.
    if (h.feed > 0) {
      EXPECT_LE(below_r, h.feed * 1.0001);
      EXPECT_GT(below_r, h.feed * 0.99);
      if (h.top > h.r + 1e-6) {
        EXPECT_GT(above_r, h.feed * 1.5);
      }
    }
    const std::vector<double> pecks = h.pecks.empty() ? std::vector<double>{h.bottom} : h.pecks;
    ASSERT_EQ(turns.size(), pecks.size());
    for (std::size_t n = 0; n < pecks.size(); ++n) {
      EXPECT_NEAR(turns[n], pecks[n], kMicron);
      f.bottom = std::max(f.bottom, std::abs(turns[n] - pecks[n]));
    }
    // The joints at the bottom: the inverse kinematics of the programmed point, which is not
    // where the machine's own X Y Z would put it.
    const motion::AxisPose bottom = joints_at(h.x, h.y, h.bottom, kTilt);
    f.joints = std::max(f.joints, pose_distance(deepest->joints, bottom));
    EXPECT_LE(pose_distance(deepest->joints, bottom), kMicron);
    // The path stops at R, where the traverse meets the feed, and at the bottom, as exact path
    // (G61, in which every cycle runs) stops out of TCP.
    int stops = 0;
    const motion::AxisPose at_r = joints_at(h.x, h.y, h.r, kTilt);
    const motion::AxisPose at_bottom = joints_at(h.x, h.y, h.bottom, kTilt);
    for (std::size_t k = 0; k + 1 < run.segments.size(); ++k) {
      const motion::Segment& seg = run.segments[k];
      const bool into_feed = seg.feed == 0 && run.segments[k + 1].feed > 0;
      if ((into_feed && pose_distance(seg.end, at_r) < 1e-9) ||
          (seg.feed > 0 && pose_distance(seg.end, at_bottom) < 1e-9)) {
        EXPECT_FALSE(seg.continuous) << "at Z" << seg.end[2];
        ++stops;
      }
    }
    EXPECT_GE(stops, 2);
    const motion::AxisPose untilted{h.x, h.y, h.bottom, kTilt, 0, 0, 0, 0, 0};
    EXPECT_GT(pose_distance(bottom, untilted), 1.0);
  }

  Figures expect_holes(const std::string& name, const std::string& text,
                       const std::vector<Hole>& holes) {
    SCOPED_TRACE(name);
    const TcpRun run = simulate(name, text);
    Figures f;
    expect_on_path(run, f);
    for (const Hole& h : holes)
      expect_hole(run, h, f);
    EXPECT_LE(f.on_axis, kMicron);
    std::printf(
        "%s: cycle time %.3f s; bottom %.2g mm, joints %.2g, on axis %.2g, on path %.2g, "
        "turning %.2g\n",
        name.c_str(), run.result.cycle_time_s, f.bottom, f.joints, f.on_axis, f.on_path, f.turning);
    return f;
  }
};

constexpr double kF100 = 100.0 / 60;

TEST_F(TcpCycles, SeedAbsoluteG81DrillsAlongTheTiltedZ) {
  // From (1, 2, 3): over (4, 5) at Z3, down to R2.8, feed to 1.5, back to the old Z 3.
  expect_holes("seed_g81_absolute.ngc", tilted(body_of(golden("seed_g81_absolute"))),
               {{4, 5, 2.8, 1.5, 3, 3, kF100}});
}

TEST_F(TcpCycles, SeedIncrementalG81WithThreeRepeats) {
  // Clear Z 4.8 (1.8 over the old Z 3), each hole 0.6 deep: 4.2.
  std::vector<Hole> holes;
  for (int n = 1; n <= 3; ++n)
    holes.push_back({1.0 + 4 * n, 2.0 + 5 * n, 4.8, 4.2, 4.8, 4.8, kF100});
  expect_holes("seed_g81_incremental_repeat.ngc",
               tilted(body_of(golden("seed_g81_incremental_repeat"))), holes);
}

TEST_F(TcpCycles, SeedG80SectionEightHoles) {
  // R1 above the old Z 0: four holes to Z0 along Y0, four to Z0.5 along Y1, F10.
  std::vector<Hole> holes;
  for (int n = 1; n <= 4; ++n)
    holes.push_back({static_cast<double>(n), 0, 1, 0, 1, 1, 10.0 / 60});
  for (int n = 1; n <= 4; ++n)
    holes.push_back({static_cast<double>(n), 1, 1, 0.5, 1, 1, 10.0 / 60});
  expect_holes("seed_g80_modal_cycle.ngc", tilted(body_of(golden("seed_g80_modal_cycle"))), holes);
}

TEST_F(TcpCycles, NumeryxCycleInOneBlock) {
  // Zi 10, g91 R-2 Z-5: R1 = 9, drilled to 3, back to Zi (g98), f300.
  const std::string program =
      body_of(slurp(std::string(CNCD_SOURCE_DIR) + "/examples/numeryx/one_block.ngc"));
  std::vector<Hole> holes;
  for (const auto& [x, y] : {std::pair{10.0, 20.0}, {30.0, 20.0}, {50.0, 40.0}})
    holes.push_back({x, y, 9, 3, 10, 10, 5});
  expect_holes("one_block.ngc", tilted(program, true), holes);
}

TEST_F(TcpCycles, G83PecksWithG99) {
  // Pecks of 2.5 from R2 to -6, back out to R between them; G99 leaves at R, so the second
  // hole is entered and left at R.
  const std::vector<double> pecks{-0.5, -3, -5.5, -6};
  expect_holes("g83.ngc", tilted("G0 X0 Y0 Z10\nF120\nG99 G83 X10 Y5 Z-6 R2 Q2.5\nX20 Y-5\n"),
               {{10, 5, 2, -6, 10, 2, 0, pecks}, {20, -5, 2, -6, 2, 2, 0, pecks}});
}

TEST_F(TcpCycles, TheOtherCyclesDrillAlongTheTiltedZ) {
  // G98 back to Z10 after each. G73 breaks the chip every 1.5 mm; G82, G86 and G89 dwell at
  // the bottom; G85, G89 and the floating G84 feed back out, G86 rapids out, the spindle stopped.
  const std::string program =
      "G0 X0 Y0 Z10\nS1000 M3\nF150\nG98 G82 X10 Y0 Z-3 R1 P0.5\nG73 X20 Z-5 R1 Q1.5\n"
      "G85 X30 Z-4 R1\nG86 X40 Z-4 R1 P0.2\nG89 X50 Z-4 R1 P0.3\nG84 X60 Z-4 R1\n";
  const double feed = 150.0 / 60;
  std::vector<Hole> holes{{10, 0, 1, -3, 10, 10, feed},
                          {20, 0, 1, -5, 10, 10, 0, {-0.5, -2, -3.5, -5}}};
  for (const double x : {30.0, 40.0, 50.0, 60.0})
    holes.push_back({x, 0, 1, -4, 10, 10, feed});
  expect_holes("cycles.ngc", tilted(program), holes);
}

TEST_F(TcpCycles, G87AndG88StayOnTheirMovesInThePartsFrame) {
  // G87 backs out of the hole's axis by I, goes down, comes back and bores up to K; G88 stops
  // the program at the bottom (the operator's hold takes no time here). Each period's tip lies
  // on the move under way, in the part's frame.
  expect_holes("g87_g88.ngc",
               tilted("S1000 M3\nG0 X10 Y0 Z10\nF120\nG98 G87 X10 Y0 Z-5 R1 I2 J0 K-2\n"
                      "G88 X20 Z-4 R1 P0.2\n"),
               {});
}

TEST_F(TcpCycles, TheTrunnionCyclesExample) {
  // examples/xyzac_trt_cycles.ngc: four G81 holes from R1 to -5 at F120, G98 to Z10; a G83
  // peck of 3 from R1 to -12 (G99); a G33.1 tap of the first hole to -4 from Z5, out to Z30.
  std::vector<Hole> holes{{10, 0, 1, -5, 30, 30, 0, {-5, -4}}};
  for (const auto& [x, y] : {std::pair{20.0, 0.0}, {20.0, 10.0}, {10.0, 10.0}})
    holes.push_back({x, y, 1, -5, 10, 10, 2});
  holes.push_back({15, 5, 1, -12, 10, 10, 0, {-2, -5, -8, -11, -12}});
  expect_holes("xyzac_trt_cycles.ngc",
               slurp(std::string(CNCD_SOURCE_DIR) + "/examples/xyzac_trt_cycles.ngc"), holes);
}

}  // namespace
}  // namespace cncd::test
