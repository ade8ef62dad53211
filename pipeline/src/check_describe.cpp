// The summaries cncd-check prints of a check: moves, extents, tools and limits; the holes.
#include <cstdio>
#include <string>

#include "cncd/pipeline/program_check.hpp"
#include "number_text.hpp"

namespace cncd::pipeline {

using interp::kAxes;

std::string describe(const CheckReport& report) {
  const char* unit = report.inch_machine ? "in" : "mm";
  std::string text =
      "moves: " + std::to_string(report.traverses + report.feeds + report.arcs) + " (" +
      std::to_string(report.traverses) + " rapid, " + std::to_string(report.feeds) + " feed, " +
      std::to_string(report.arcs) + " arc), " + std::to_string(report.dwells) + " dwell" +
      (report.dwells == 1 ? "" : "s") + ", " + std::to_string(report.blocks) + " blocks\n";
  text += std::string("extents (machine coordinates, ") + unit + "):\n";
  bool any = false;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (!report.moved[axis]) continue;
    any = true;
    const bool angular = axis >= 3 && axis <= 5;
    text += std::string("  ") + config::kAxisLetters[axis] + " " + fixed4(report.min[axis]) +
            " .. " + fixed4(report.max[axis]) + (angular ? " deg" : "") + "\n";
  }
  if (!any) text += "  (no axis moves)\n";
  text += "tools:";
  if (report.tools.empty()) text += " none";
  for (const int tool : report.tools)
    text += " T" + std::to_string(tool);
  text += "\nfeed path: " + fixed4(report.feed_length) + " " + unit + "\n";
  if (!report.limits_checked) {
    text += "soft limits: not checked (no --ini; interpreter defaults)\n";
  } else if (report.limit_violations == 0) {
    text += "soft limits: every move within them\n";
  } else {
    text += "soft limits: " + std::to_string(report.limit_violations) + " violation" +
            (report.limit_violations == 1 ? "" : "s") + "\n";
  }
  return text;
}

std::string describe_holes(const CheckReport& report) {
  std::string text = "holes: " + std::to_string(report.holes.size()) + " (machine coordinates, " +
                     (report.inch_machine ? "in" : "mm") + ")\n";
  char row[160];
  std::snprintf(row, sizeof row, "%5s %7s %12s %12s %12s %12s\n", "hole", "line", "X", "Y", "top",
                "bottom");
  text += row;
  for (std::size_t n = 0; n < report.holes.size(); ++n) {
    const Hole& h = report.holes[n];
    std::snprintf(row, sizeof row, "%5zu %7d %12s %12s %12s %12s\n", n + 1, h.line,
                  fixed4(h.x).c_str(), fixed4(h.y).c_str(), fixed4(h.top).c_str(),
                  fixed4(h.bottom).c_str());
    text += row;
  }
  return text;
}

}  // namespace cncd::pipeline
