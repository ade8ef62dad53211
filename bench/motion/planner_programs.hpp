// The planner benchmark's machine and programs, generated so that every figure can be
// reproduced: a small fast mill (X/Y 200 mm/s and 2000 mm/s^2, Z 100 mm/s and 1000 mm/s^2,
// 1 ms servo period) as a cncd INI and as a LinuxCNC INI derived from LinuxCNC's sim
// axis_mm.ini, and the programs (a) to (d) of the motion issue and (e), a 3D surface finish of
// 200,000 lines.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cncd/motion/types.hpp"

namespace cncd::bench {

struct BenchProgram {
  std::string name;
  std::filesystem::path path;
  bool exact_stop = false;  // canned cycles: judge against the exact-stop bound
  // The dense blended path: the program's lines path_first_line to path_last_line (0: none);
  // the first of them names its motion mode and feed, and the program's first prelude_lines
  // lines set the modes it runs in.
  int path_first_line = 0;
  int path_last_line = 0;
  int prelude_lines = 0;
  double tolerance = 0;        // the path's G64 P (0: none), for the reference within P
  double merge_tolerance = 0;  // its G64 Q (P when only P is given)
  bool diagnose = false;       // print where the time goes along the path
};

// Writes the cncd INI (sim drives) into `dir`; returns its path.
std::filesystem::path write_cncd_ini(const std::filesystem::path& dir);
// Writes a LinuxCNC INI with the same limits, from `axis_mm_ini`, into `dir`; returns its
// path, or an empty path (and `error`) when the sample config cannot be read.
std::filesystem::path write_linuxcnc_ini(const std::filesystem::path& dir,
                                         const std::filesystem::path& axis_mm_ini,
                                         std::string& error);
// Writes the generated programs into `dir` and lists them with 3D_Chips.ngc (when found).
std::vector<BenchProgram> write_programs(const std::filesystem::path& dir,
                                         const std::filesystem::path& chips_ngc);
// Writes `program`'s dense path alone into `dir` (<stem>_path.ngc): its prelude, G92 making
// `start` (where the path starts, program units) the current position wherever the machine
// stands, the path's lines, G92.1 and M2. Returns its path, empty when it cannot.
std::filesystem::path write_path_alone(const BenchProgram& program,
                                       const std::filesystem::path& dir,
                                       const motion::AxisPose& start);

}  // namespace cncd::bench
