// The planner benchmark's machine and programs, generated so that every figure can be
// reproduced: a small fast mill (X/Y 200 mm/s and 2000 mm/s^2, Z 100 mm/s and 1000 mm/s^2,
// 1 ms servo period) as a cncd INI and as a LinuxCNC INI derived from LinuxCNC's sim
// axis_mm.ini, and the programs (a) to (d) of the motion issue.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace cncd::bench {

struct BenchProgram {
  std::string name;
  std::filesystem::path path;
  bool exact_stop = false;  // canned cycles: judge against the exact-stop bound
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

}  // namespace cncd::bench
