// The toolpath preview: decimation within its tolerance (and the budget that widens it), the
// kinds and lines of its pieces, arcs as the planner builds them, offsets, and
// `cncd-check --preview` with the same extents as the check's summary.
#include <openssl/evp.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/pipeline/program_preview.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

using pipeline::PieceKind;
using Xyz = std::array<double, 3>;

double to_segment(const Xyz& p, const Xyz& a, const Xyz& b) {
  Xyz ab{}, ap{};
  double length2 = 0, dot = 0;
  for (int i = 0; i < 3; ++i) {
    ab[i] = b[i] - a[i];
    ap[i] = p[i] - a[i];
    length2 += ab[i] * ab[i];
    dot += ap[i] * ab[i];
  }
  const double t = length2 > 0 ? std::clamp(dot / length2, 0.0, 1.0) : 0.0;
  return std::hypot(ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]);
}

double to_polyline(const Xyz& p, const std::vector<Xyz>& line) {
  double best = INFINITY;
  for (std::size_t i = 0; i + 1 < line.size(); ++i)
    best = std::min(best, to_segment(p, line[i], line[i + 1]));
  return line.size() == 1 ? to_segment(p, line[0], line[0]) : best;
}

// The preview's points, polyline by polyline.
std::vector<std::vector<Xyz>> polylines(const pipeline::Preview& preview) {
  std::vector<std::vector<Xyz>> out;
  std::size_t at = 0;
  for (const std::uint32_t count : preview.counts) {
    out.emplace_back();
    for (std::uint32_t k = 0; k < count; ++k, ++at)
      out.back().push_back({preview.xyz[3 * at], preview.xyz[3 * at + 1], preview.xyz[3 * at + 2]});
  }
  return out;
}

interp::Pose pose(double x, double y, double z) {
  interp::Pose p{};
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

TEST(Preview, ThinningKeepsBothEndsAndPassesWithinTheToleranceOfEveryPointItDrops) {
  std::mt19937 random(7);
  std::normal_distribution<double> step(0, 0.05);
  for (int round = 0; round < 10; ++round) {
    std::vector<Xyz> walk{{0, 0, 0}};
    for (int i = 0; i < 1000; ++i)
      walk.push_back({walk.back()[0] + 0.1, walk.back()[1] + step(random), step(random)});
    const double tolerance = 0.04 * (round + 1);
    const auto thinned = pipeline::thin_polyline(walk, tolerance);
    ASSERT_EQ(thinned.front(), walk.front());
    ASSERT_EQ(thinned.back(), walk.back());
    EXPECT_LT(thinned.size(), walk.size());
    for (const Xyz& p : walk)
      ASSERT_LE(to_polyline(p, thinned), tolerance + 1e-12);
  }
}

TEST(Preview, EveryPointOfARandomPathIsWithinTheReportedToleranceEvenPastTheBudget) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  // A tolerance far below the path's detail thins nothing at first: the budget holds anyway.
  const std::vector<std::pair<double, std::size_t>> cases = {
      {0.01, 1024}, {0.01, 1'000'000}, {1e-9, 1024}};
  for (const auto& [asked, budget] : cases) {
    pipeline::PreviewBuilder builder({asked, budget});
    std::vector<Xyz> path{{0, 0, 0}};
    for (int i = 0; i < 5000; ++i) {
      const Xyz next{path.back()[0] + 0.05, std::sin(i * 0.04) * 5 + jitter(random) * 0.1,
                     jitter(random)};
      builder.move(PieceKind::feed, pose(path.back()[0], path.back()[1], path.back()[2]),
                   pose(next[0], next[1], next[2]), i + 1);
      builder.end_block(false, {});
      path.push_back(next);
    }
    const pipeline::Preview preview = builder.finish();
    ASSERT_EQ(preview.counts.size(), 1u);
    EXPECT_LE(preview.lines.size(), budget);
    EXPECT_EQ(preview.source_points, path.size());
    EXPECT_GE(preview.tolerance, asked);
    // The small budget made it thin the path again, at a wider tolerance.
    if (budget == 1024) {
      EXPECT_GT(preview.tolerance, 2 * asked);
    }
    // float32 points: a few micrometres of rounding on top.
    const auto drawn = polylines(preview).front();
    for (const Xyz& p : path)
      ASSERT_LE(to_polyline(p, drawn), preview.tolerance + 1e-4);
    EXPECT_EQ(preview.lines.front(), 1u);
    EXPECT_EQ(preview.lines.back(), 5000u);
  }
}

TEST(Preview, CollinearMovesBecomeOneLineAndKindsStartNewPolylines) {
  pipeline::PreviewBuilder builder({0.01, 300'000});
  builder.move(PieceKind::rapid, pose(0, 0, 0), pose(0, 0, 5), 1);
  builder.end_block(false, {});
  for (int i = 0; i < 100; ++i)
    builder.move(PieceKind::feed, pose(i, 0, 5), pose(i + 1, 0, 5), 2 + i);
  builder.end_block(false, {});
  builder.move(PieceKind::feed, pose(100, 0, 5), pose(100, 0, 0), 200);  // a drill cycle's feed
  builder.move(PieceKind::rapid, pose(100, 0, 0), pose(100, 0, 5), 200);
  builder.end_block(true, {});
  builder.move(PieceKind::probe, pose(100, 0, 5), pose(100, 0, -1), 201);
  pipeline::PreviewFrame g55;
  g55.origin = {10, 20, 0};
  builder.end_block(false, g55);
  const pipeline::Preview preview = builder.finish();
  ASSERT_EQ(preview.kinds, (std::vector<PieceKind>{PieceKind::rapid, PieceKind::feed,
                                                   PieceKind::cycle, PieceKind::probe}));
  EXPECT_EQ(preview.counts, (std::vector<std::uint32_t>{2, 2, 3, 2}));
  EXPECT_EQ(preview.frame_of, (std::vector<std::uint32_t>{0, 0, 0, 1}));
  ASSERT_EQ(preview.frames.size(), 2u);
  EXPECT_EQ(preview.frames[1].origin, (std::array<double, 3>{10, 20, 0}));
  // The feed line's end carries the line of the last move merged into it.
  EXPECT_EQ(preview.lines[3], 101u);
}

TEST(Preview, ALongPolylineGoesOnFromItsLastPointInPiecesOfBoundedLength) {
  pipeline::PreviewBuilder builder({0.001, 1'000'000});
  for (int i = 0; i < 40'000; ++i) {
    builder.move(PieceKind::feed, pose(i, i % 2, 0), pose(i + 1, (i + 1) % 2, 0), i + 1);
    builder.end_block(false, {});
  }
  const pipeline::Preview preview = builder.finish();
  ASSERT_GT(preview.counts.size(), 1u);
  const auto drawn = polylines(preview);
  std::size_t points = 0;
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    EXPECT_LE(drawn[k].size(), 16384u);
    EXPECT_EQ(preview.kinds[k], PieceKind::feed);
    if (k > 0) {
      EXPECT_EQ(drawn[k].front(), drawn[k - 1].back()) << "piece " << k;
    }
    points += drawn[k].size() - (k > 0 ? 1 : 0);
  }
  EXPECT_EQ(points, 40'001u);  // a zigzag keeps every corner
}

TEST(Preview, AnArcIsDrawnWithinTheToleranceOfItsCircle) {
  TempDir dir;
  const auto program =
      dir.write("arc.ngc", "G21 G90 G17\nG0 X10 Y0 Z0\nG2 X-10 Y0 I-10 J0 F500\nM2\n");
  pipeline::CheckOptions options;
  const auto result = pipeline::preview_program(program, options, {0.005, 300'000});
  ASSERT_TRUE(result.report.ok());
  const auto drawn = polylines(result.preview);
  ASSERT_EQ(result.preview.kinds.back(), PieceKind::arc);
  const auto& arc = drawn.back();
  EXPECT_GT(arc.size(), 20u);
  for (std::size_t i = 0; i < arc.size(); ++i) {
    EXPECT_NEAR(std::hypot(arc[i][0], arc[i][1]), 10, 1e-4);
    EXPECT_LE(arc[i][1], 1e-6) << "a clockwise half circle from X10 to X-10 stays below Y0";
  }
  // The sag of each chord: the circle never leaves the drawing by more than the tolerance.
  for (std::size_t i = 0; i + 1 < arc.size(); ++i) {
    const double half = std::hypot(arc[i + 1][0] - arc[i][0], arc[i + 1][1] - arc[i][1]) / 2;
    EXPECT_LE(10 - std::sqrt(100 - half * half), 0.005 + 1e-6);
  }
  EXPECT_EQ(result.preview.lines.back(), 3u);
}

std::vector<unsigned char> unbase64(const std::string& text) {
  std::vector<unsigned char> bytes(text.size() / 4 * 3 + 3);
  const int n = EVP_DecodeBlock(bytes.data(), reinterpret_cast<const unsigned char*>(text.data()),
                                static_cast<int>(text.size()));
  bytes.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
  // EVP_DecodeBlock counts the padding as zero bytes.
  const std::size_t padding = text.ends_with("==") ? 2 : text.ends_with("=") ? 1 : 0;
  bytes.resize(bytes.size() - std::min(padding, bytes.size()));
  return bytes;
}

TEST(Preview, CncdCheckPrintsThePathWithTheExtentsOfItsSummary) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path());
  const auto program = dir.write("g81.ngc",
                                 "G21 G17 G90 G94\nF100\nG0 X1 Y2 Z3\nG90 G81 G98 X4 Y5 Z1.5 "
                                 "R2.8\nG80\nM2\n");
  const auto preview =
      run_command({CNCD_CHECK_BINARY, "--preview", "--ini", ini.string(), program.string()});
  ASSERT_EQ(preview.exit_status, 0) << preview.err;
  const auto json = nlohmann::json::parse(preview.out);
  EXPECT_EQ(json["extents"]["X"], nlohmann::json({1.0, 4.0}));
  EXPECT_EQ(json["extents"]["Y"], nlohmann::json({2.0, 5.0}));
  EXPECT_EQ(json["extents"]["Z"], nlohmann::json({1.5, 3.0}));
  const auto summary = run_command({CNCD_CHECK_BINARY, "--ini", ini.string(), program.string()});
  EXPECT_NE(summary.out.find("  Z 1.5000 .. 3.0000"), std::string::npos) << summary.out;
  // The cycle: over the hole at the old Z, down to Z1.5, back up to Z3, all tagged line 4.
  const auto kinds = unbase64(json["polyline_kind"]);
  ASSERT_EQ(kinds, (std::vector<unsigned char>{0, 3}));
  const auto xyz = unbase64(json["xyz"]);
  const auto lines = unbase64(json["line"]);
  ASSERT_EQ(xyz.size(), 6u * 12u);
  ASSERT_EQ(lines.size(), 6u * 4u);
  std::vector<float> points(18);
  std::memcpy(points.data(), xyz.data(), xyz.size());
  EXPECT_EQ(std::vector<float>(points.begin() + 6, points.end()),
            (std::vector<float>{1, 2, 3, 4, 5, 3, 4, 5, 1.5, 4, 5, 3}));
  EXPECT_EQ(lines[5 * 4], 4);
  const auto bad = run_command({CNCD_CHECK_BINARY, "--preview", "--tolerance", "0", "x.ngc"});
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("--tolerance needs a number above 0"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace cncd::test
