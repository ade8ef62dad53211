#include "cncd/pipeline/preview.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "cncd/config/enum_name.hpp"

namespace cncd::pipeline {
namespace {

using Xyz = std::array<double, 3>;

// Points since the last kept one are tested against every new chord: a bounded run keeps the
// work per point bounded on long straight stretches.
constexpr std::size_t kMaxRun = 256;
// A polyline longer than this goes on as another one from its last point: the budget then
// counts every point kept, and thinning works on bounded pieces.
constexpr std::size_t kMaxPolyline = 16384;

double distance_to_segment(const Xyz& p, const Xyz& a, const Xyz& b) {
  const Xyz ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Xyz ap{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double length2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
  double t = length2 > 0 ? (ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]);
}

// Douglas-Peucker over `at(i)`, i in [0, n): which points to keep.
template <typename At>
std::vector<bool> keep_points(std::size_t n, double tolerance, const At& at) {
  std::vector<bool> keep(n, false);
  if (n == 0) return keep;
  keep.front() = keep.back() = true;
  std::vector<std::pair<std::size_t, std::size_t>> stack;
  if (n > 2) stack.emplace_back(0, n - 1);
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    double worst = -1;
    std::size_t worst_at = first;
    for (std::size_t i = first + 1; i < last; ++i) {
      const double d = distance_to_segment(at(i), at(first), at(last));
      if (d > worst) {
        worst = d;
        worst_at = i;
      }
    }
    if (worst > tolerance) {
      keep[worst_at] = true;
      if (worst_at - first > 1) stack.emplace_back(first, worst_at);
      if (last - worst_at > 1) stack.emplace_back(worst_at, last);
    }
  }
  return keep;
}

}  // namespace

const char* piece_kind_name(PieceKind kind) {
  static constexpr const char* kNames[] = {"rapid", "feed", "arc", "cycle", "probe"};
  return config::enum_name(kind, kNames);
}

std::vector<Xyz> thin_polyline(const std::vector<Xyz>& points, double tolerance) {
  const auto keep =
      keep_points(points.size(), tolerance, [&](std::size_t i) -> const Xyz& { return points[i]; });
  std::vector<Xyz> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (keep[i]) out.push_back(points[i]);
  return out;
}

PreviewBuilder::PreviewBuilder(PreviewOptions options) : options_(options) {
  options_.tolerance = std::max(options_.tolerance, 0.0);
  options_.max_points = std::max<std::size_t>(options_.max_points, 1024);
}

void PreviewBuilder::move(PieceKind kind, const interp::Pose& from, const interp::Pose& to,
                          int line) {
  const auto tag = static_cast<std::uint32_t>(std::max(line, 0));
  block_.push_back({kind, {{from[0], from[1], from[2]}, tag}, {{to[0], to[1], to[2]}, tag}});
}

void PreviewBuilder::end_block(bool cycle, const PreviewFrame& frame) {
  if (block_.empty()) return;
  if (frames_.empty() || frames_.back() != frame) frames_.push_back(frame);
  const auto frame_index = static_cast<std::uint32_t>(frames_.size() - 1);
  for (const Raw& raw : block_) {
    const bool straight = raw.kind == PieceKind::rapid || raw.kind == PieceKind::feed;
    add(cycle && straight ? PieceKind::cycle : raw.kind, frame_index, raw.from, raw.to);
  }
  block_.clear();
}

void PreviewBuilder::add(PieceKind kind, std::uint32_t frame, const Point& from, const Point& to) {
  ++source_points_;
  const Point* last = !open_             ? nullptr
                      : pending_.empty() ? &current_.points.back()
                                         : &pending_.back();
  if (last == nullptr || current_.kind != kind || current_.frame != frame || last->at != from.at) {
    close_run();
    open_ = true;
    current_.kind = kind;
    current_.frame = frame;
    current_.points.assign(1, from);
    ++source_points_;
  } else if (last->at == to.at) {
    return;  // no length: nothing to draw
  }
  // Once the path has been thinned, what comes next is decimated to the tolerance reached.
  const double tolerance = options_.tolerance + extra_;
  const Xyz& anchor = current_.points.back().at;
  bool fits = pending_.size() < kMaxRun;
  for (std::size_t i = 0; fits && i < pending_.size(); ++i)
    fits = distance_to_segment(pending_[i].at, anchor, to.at) <= tolerance;
  if (!fits) {
    current_.points.push_back(pending_.back());
    pending_.clear();
    if (current_.points.size() >= kMaxPolyline) {
      const Point end = current_.points.back();
      close_run();
      open_ = true;
      current_.kind = kind;
      current_.frame = frame;
      current_.points.assign(1, end);
    }
  }
  pending_.push_back(to);
}

void PreviewBuilder::close_run() {
  if (!open_) return;
  open_ = false;
  if (!pending_.empty()) current_.points.push_back(pending_.back());
  pending_.clear();
  kept_ += current_.points.size();
  done_.push_back(std::move(current_));
  current_ = {};
  if (kept_ > options_.max_points) thin_all();
}

void PreviewBuilder::thin_all() {
  // Each pass doubles the tolerance reached, until the points fit in three quarters of the
  // budget or only the ends of polylines are left.
  while (kept_ > options_.max_points * 3 / 4) {
    std::size_t inner = 0;
    for (const Polyline& polyline : done_)
      inner += polyline.points.size() > 2 ? polyline.points.size() - 2 : 0;
    if (inner == 0) break;
    const double step = std::max(options_.tolerance + extra_, 1e-6);
    std::size_t kept = 0;
    for (Polyline& polyline : done_) {
      const auto& points = polyline.points;
      const auto keep = keep_points(points.size(), step,
                                    [&](std::size_t i) -> const Xyz& { return points[i].at; });
      std::vector<Point> thinned;
      for (std::size_t i = 0; i < points.size(); ++i)
        if (keep[i]) thinned.push_back(points[i]);
      polyline.points = std::move(thinned);
      kept += polyline.points.size();
    }
    extra_ += step;
    kept_ = kept;
  }
}

Preview PreviewBuilder::finish() {
  if (!block_.empty()) end_block(false, frames_.empty() ? PreviewFrame{} : frames_.back());
  close_run();
  Preview out;
  out.tolerance = options_.tolerance + extra_;
  out.source_points = source_points_;
  out.frames = std::move(frames_);
  out.xyz.reserve(kept_ * 3);
  out.lines.reserve(kept_);
  for (const Polyline& polyline : done_) {
    out.kinds.push_back(polyline.kind);
    out.counts.push_back(static_cast<std::uint32_t>(polyline.points.size()));
    out.frame_of.push_back(polyline.frame);
    for (const Point& point : polyline.points) {
      for (const double v : point.at)
        out.xyz.push_back(static_cast<float>(v));
      out.lines.push_back(point.line);
    }
  }
  *this = PreviewBuilder(options_);
  return out;
}

}  // namespace cncd::pipeline
