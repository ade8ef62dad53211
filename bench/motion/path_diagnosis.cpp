#include "path_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace cncd::bench {
namespace {

struct Row {
  std::string name;
  std::size_t moves = 0;
  double cncd = 0, planned = 0, reference = 0;
};

// Rows named by the upper edges of their classes (the last open-ended).
std::vector<Row> rows(const std::vector<double>& edges, const char* unit, const char* below,
                      int digits) {
  std::vector<Row> out;
  char text[64];
  for (std::size_t k = 0; k <= edges.size(); ++k) {
    if (k == 0)
      std::snprintf(text, sizeof text, "%s %.*f %s", below, digits, edges[0], unit);
    else if (k == edges.size())
      std::snprintf(text, sizeof text, ">= %.*f %s", digits, edges[k - 1], unit);
    else
      std::snprintf(text, sizeof text, "%.*f .. %.*f %s", digits, edges[k - 1], digits, edges[k],
                    unit);
    out.push_back({text});
  }
  return out;
}

std::size_t bin(const std::vector<double>& edges, double value) {
  return static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), value) -
                                  edges.begin());
}

void print(const char* title, const std::vector<Row>& table) {
  std::printf("    %-24s %7s %9s %9s %9s %9s %9s %9s\n", title, "moves", "cncd s", "planned s",
              "ref s", "lost s", "limits s", "running s");
  for (const Row& r : table) {
    if (r.moves == 0) continue;
    std::printf("    %-24s %7zu %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f\n", r.name.c_str(), r.moves,
                r.cncd, r.planned, r.reference, r.cncd - r.reference, r.planned - r.reference,
                r.cncd - r.planned);
  }
}

// Unit tangents at a move's start and end (a merged line's from its ends).
void directions(const motion::Segment& move, motion::AxisPose& start, motion::AxisPose& end) {
  start = move.start_direction;
  end = move.end_direction;
  if (move.kind != motion::Segment::Kind::line || move.length <= 0) return;
  double sum = 0;
  for (int k = 0; k < motion::kAxes; ++k)
    sum += (move.end[k] - move.start[k]) * (move.end[k] - move.start[k]);
  for (int k = 0; k < motion::kAxes; ++k)
    start[k] = end[k] = (move.end[k] - move.start[k]) / std::sqrt(sum);
}

}  // namespace

void print_diagnosis(const config::MachineConfig& machine,
                     const std::vector<motion::Segment>& moves, double merge_tolerance,
                     const std::vector<double>& cncd_s, const PathReference& reference,
                     const PathReference& planned, const PathReference& axis_blend_speeds) {
  const std::size_t n = moves.size();
  if (cncd_s.size() != n || reference.move_s.size() != n || planned.move_s.size() != n) {
    std::printf("    (diagnosis: the moves counted do not match)\n");
    return;
  }
  std::vector<std::size_t> last;
  const auto path = merged_path(moves, merge_tolerance, last);
  const double period = static_cast<double>(machine.servo_period_ns) * 1e-9;
  const std::vector<double> angle_edges = {0.1, 0.5, 1, 2, 5, 10, 30, 90};
  const std::vector<double> length_edges = {0.05, 0.1, 0.2, 0.5, 1, 2, 5};
  const std::vector<double> ratio_edges = {0.5, 0.7, 0.8, 0.9, 0.95, 1.0};
  const std::vector<double> period_edges = {1, 2, 5};
  auto by_angle = rows(angle_edges, "deg", "<", 1);
  by_angle.push_back({"first move"});
  auto by_length = rows(length_edges, "mm", "<", 2);
  auto by_ratio = rows(ratio_edges, "", "<", 2);
  auto by_periods = rows(period_edges, "periods", "<", 0);
  Row all{"whole path"};
  motion::AxisPose before{}, start{}, end{};
  for (std::size_t g = 0, i = 0; g < path.size(); ++g) {
    Row one;
    for (; i <= last[g]; ++i) {
      ++one.moves;
      one.cncd += cncd_s[i];
      one.planned += planned.move_s[i];
      one.reference += reference.move_s[i];
    }
    const auto add = [&one](Row& row) {
      row.moves += one.moves;
      row.cncd += one.cncd;
      row.planned += one.planned;
      row.reference += one.reference;
    };
    add(all);
    directions(path[g], start, end);
    if (g == 0) {
      add(by_angle.back());
    } else {
      double c = 0;
      for (int k = 0; k < motion::kAxes; ++k)
        c += before[k] * start[k];
      add(by_angle[bin(angle_edges, std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi)]);
    }
    before = end;
    add(by_length[bin(length_edges, path[g].length)]);
    add(by_ratio[bin(ratio_edges, one.cncd > 0 ? one.reference / one.cncd : 1.0)]);
    add(by_periods[bin(period_edges, one.reference / period)]);
  }
  std::printf(
      "  where the time goes along the path alone (cncd; planned: the planner's segments timed "
      "with the whole path in view; ref: the reference within P and Q; lost = cncd - ref = "
      "limits (planned - ref) + running (cncd - planned)); by the moves the planner runs (%zu "
      "after merging within Q %g):\n",
      path.size(), merge_tolerance);
  print("", {all});
  std::printf(
      "    of the limits: blend arcs' speed limits %.3f s (raised to what each axis allows on "
      "its share of their curvature: %.3f s), the rest (their acceleration, the grid) %.3f s\n",
      planned.time_s - axis_blend_speeds.time_s, axis_blend_speeds.time_s,
      axis_blend_speeds.time_s - all.reference);
  print("corner angle at its start", by_angle);
  print("length", by_length);
  print("cncd speed / reference", by_ratio);
  print("reference time", by_periods);
}

}  // namespace cncd::bench
