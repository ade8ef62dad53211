// A program's toolpath for display: the XYZ path the machine will follow (the check's own
// moves, arcs as the planner builds them), in machine coordinates and units, as polylines of
// one kind each, every point tagged with the program line of the move that ends there. The
// points are decimated as they come: a point is dropped when the polyline without it stays
// within `tolerance` of it. Past `max_points` the polylines are thinned again at twice the
// tolerance reached so far, so a preview never outgrows its budget however long the program.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cncd/interp/canon.hpp"

namespace cncd::pipeline {

enum class PieceKind : std::uint8_t { rapid, feed, arc, cycle, probe };
const char* piece_kind_name(PieceKind kind);

// 0.01 mm, or 0.0004 in on an inch machine.
inline double default_preview_tolerance(bool inch_machine) {
  return inch_machine ? 0.0004 : 0.01;
}

struct PreviewOptions {
  double tolerance = 0.01;  // machine units
  std::size_t max_points = 300'000;
};

// The offsets in force for a stretch of the path: work = rotate_xy(machine - origin,
// -rotation_deg) - g92, as the DRO reads it (origin: G54..G59.3 offset plus tool length).
struct PreviewFrame {
  std::array<double, 3> origin{};
  std::array<double, 3> g92{};
  double rotation_deg = 0;
  bool operator==(const PreviewFrame&) const = default;
};

struct Preview {
  double tolerance = 0;           // the largest distance of a dropped point from the path
  std::size_t source_points = 0;  // points before decimation
  std::vector<PreviewFrame> frames;
  // Per polyline: its kind, its number of points, its frame (index into `frames`).
  std::vector<PieceKind> kinds;
  std::vector<std::uint32_t> counts;
  std::vector<std::uint32_t> frame_of;
  // Per point: x, y, z (machine coordinates and units) and the program line.
  std::vector<float> xyz;
  std::vector<std::uint32_t> lines;
};

class PreviewBuilder {
 public:
  explicit PreviewBuilder(PreviewOptions options = {});
  // A straight piece of path of the block being read (arcs come as their chords).
  void move(PieceKind kind, const interp::Pose& from, const interp::Pose& to, int line);
  // The block's pieces are final: those of a canned cycle are drawn as such, in `frame`.
  void end_block(bool cycle, const PreviewFrame& frame);
  bool has_block() const { return !block_.empty(); }
  double tolerance() const { return options_.tolerance; }
  // The preview so far (the builder is left empty).
  Preview finish();

 private:
  struct Point {
    std::array<double, 3> at;
    std::uint32_t line;
  };
  struct Raw {
    PieceKind kind;
    Point from;
    Point to;
  };
  struct Polyline {
    PieceKind kind;
    std::uint32_t frame;
    std::vector<Point> points;
  };
  void add(PieceKind kind, std::uint32_t frame, const Point& from, const Point& to);
  void close_run();
  void thin_all();

  PreviewOptions options_;
  double extra_ = 0;  // tolerance of the thinning passes so far
  std::vector<Raw> block_;
  std::vector<PreviewFrame> frames_;
  std::vector<Polyline> done_;
  std::size_t kept_ = 0;  // points in done_
  // The polyline being built: its kept points, and the points since its last kept one that
  // the chord from there to the newest point still passes within tolerance.
  bool open_ = false;
  Polyline current_{};
  std::vector<Point> pending_;
  std::size_t source_points_ = 0;
};

// Decimates `points` (Douglas-Peucker): the result keeps both ends and passes within
// `tolerance` of every point dropped. Exposed for tests.
std::vector<std::array<double, 3>> thin_polyline(const std::vector<std::array<double, 3>>& points,
                                                 double tolerance);

}  // namespace cncd::pipeline
