// The picture of the planner benchmark's speed along a piece of a path: path speed against
// path length, cncd's (from the servo loop's samples) against the time-optimal reference's
// and the programmed feed, as an SVG written by hand (plain text, no library).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cncd/motion/segment.hpp"
#include "path_reference.hpp"

namespace cncd::bench {

// A curve of the picture: points (s, v) in order of s.
struct SpeedCurve {
  std::string label;
  std::string colour;  // an SVG colour
  double width = 1.5;  // stroke width, px
  bool dashed = false;
  std::vector<double> s, v;
  bool scales = true;  // false: the speed axis is not stretched to fit it (clipped at the top)
};

// Tick values for an axis from lo to hi: multiples of 1, 2 or 5 x 10^k, at most `most` of them
// and as many as that allows, from the first multiple at or above lo to the last at or below hi.
std::vector<double> nice_ticks(double lo, double hi, int most);

// The window [from, from + width] of s where curve `slow` takes the most time over `fast`
// (each timed as the integral of ds / v, linear in v between points), its start on a grid of
// `step` from the first point of `fast`; {0, width} when the curves are shorter than it.
struct Window {
  double from = 0;
  double to = 0;
};
Window slowest_window(const SpeedCurve& slow, const SpeedCurve& fast, double width, double step);

// The curves' points within `window`, drawn on a `width` x `height` px picture with axes,
// ticks, labels and a legend; `title` above it. Returns the SVG text.
std::string speed_svg(const std::vector<SpeedCurve>& curves, Window window,
                      const std::string& title, int width = 900, int height = 420);

// The picture for the planner benchmark, written to `file`: the path speed along the path
// alone named `name`, cncd's from its servo samples (XYZ positions every `period` s from the
// path's start), the reference's `profile` and the feed of the move each of its points counts
// in (`moves`, the path's programmed moves; a feed far above the reference named in the
// legend, off the scale), over `window` or by default the 40 mm where cncd loses most.
struct SpeedPicture {
  Window window;
  double reference_length = 0;         // the path's, as the reference rounds it
  double cncd_length = 0;              // cncd's samples'
  double cncd_s = 0, reference_s = 0;  // their times over the window
};
SpeedPicture write_speed_picture(const std::filesystem::path& file, const std::string& name,
                                 double period, const std::vector<motion::Segment>& moves,
                                 const std::vector<SpeedPoint>& profile,
                                 const std::vector<motion::AxisPose>& samples,
                                 std::optional<Window> window);

}  // namespace cncd::bench
