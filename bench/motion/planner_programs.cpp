#include "planner_programs.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

namespace cncd::bench {
namespace {

namespace fs = std::filesystem;

constexpr double kXyVelocity = 200;  // mm/s
constexpr double kXyAcceleration = 2000;
constexpr double kZVelocity = 100;
constexpr double kZAcceleration = 1000;
// Vector limits high enough that only the axes limit the motion, on both controllers.
constexpr double kLinearVelocity = 400;
constexpr double kLinearAcceleration = 10000;
constexpr double kLimit = 1000;  // soft limits +-1000 mm, Z +-500 mm

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4f", value);
  return text;
}

std::string axis_section(char letter, bool joint, int index) {
  const bool z = letter == 'Z';
  const double limit = z ? kLimit / 2 : kLimit;
  std::ostringstream out;
  out << (joint ? "[JOINT_" + std::to_string(index) + "]\n"
                : std::string("[AXIS_") + letter + "]\n")
      << "MIN_LIMIT = " << -limit << "\nMAX_LIMIT = " << limit
      << "\nMAX_VELOCITY = " << (z ? kZVelocity : kXyVelocity)
      << "\nMAX_ACCELERATION = " << (z ? kZAcceleration : kXyAcceleration) << "\n";
  if (joint) {
    out << "TYPE = LINEAR\nDRIVER = sim\nFERROR = 1\nMIN_FERROR = 0.25\nHOME = 0\n"
           "HOME_OFFSET = 0\nHOME_SEARCH_VEL = 0\nHOME_LATCH_VEL = 0\nHOME_SEQUENCE = 0\n";
  }
  return out.str();
}

// Z over the surfacing raster: gentle enough that full feed stays within Z's limits.
double surface_z(double x, double y) {
  return -1.0 +
         0.5 * std::sin(2 * std::numbers::pi * x / 20) * std::cos(2 * std::numbers::pi * y / 30);
}

// (a) rows of 0.1 mm G1 segments along X over a 40 x 10 mm patch, 0.5 mm step-over.
void write_raster(const fs::path& path, int feed) {
  std::ofstream out(path);
  out << "(planner bench: 3D surfacing raster, 0.1 mm G1 segments, F" << feed << ", G64)\n"
      << "G21 G17 G40 G49 G80 G90 G94 G54\nG64\nG0 Z5\nG0 X0 Y0\nG1 Z" << number(surface_z(0, 0))
      << " F" << feed << "\n";
  constexpr int kRows = 21;
  constexpr int kSteps = 400;
  for (int row = 0; row < kRows; ++row) {
    const double y = 0.5 * row;
    if (row > 0) out << "Y" << number(y) << " Z" << number(surface_z(row % 2 ? 40 : 0, y)) << "\n";
    for (int k = 1; k <= kSteps; ++k) {
      const double x = 0.1 * (row % 2 ? kSteps - k : k);
      out << "X" << number(x) << " Z" << number(surface_z(x, y)) << "\n";
    }
  }
  out << "G0 Z5\nM2\n";
}

// (b) a circle of 0.1 mm chords at F9000: radius 30 mm keeps the centripetal acceleration at
// 150^2 / 30 = 750 mm/s^2, well within 2000.
void write_circle(const fs::path& path) {
  std::ofstream out(path);
  constexpr double kRadius = 30;
  const int chords = static_cast<int>(std::round(2 * std::numbers::pi * kRadius / 0.1));
  out << "(planner bench: circle R30 of " << chords << " chords of 0.1 mm, F9000, G64)\n"
      << "G21 G17 G40 G49 G80 G90 G94 G54\nG64\nG0 Z1\nG0 X" << number(kRadius)
      << " Y0\nG1 Z0 F9000\n";
  for (int i = 1; i <= chords; ++i) {
    const double t = 2 * std::numbers::pi * i / chords;
    out << "X" << number(kRadius * std::cos(t)) << " Y" << number(kRadius * std::sin(t)) << "\n";
  }
  out << "G0 Z1\nM2\n";
}

// (c) a 6 x 5 grid: G81 rows (G99 and G98) and G83 peck rows.
void write_drilling(const fs::path& path) {
  std::ofstream out(path);
  out << "(planner bench: drilling grid, G81 and G83)\n"
      << "G21 G17 G40 G49 G80 G90 G94 G54\nG0 Z10\nG0 X0 Y0\n"
      << "G99 G81 X0 Y0 Z-5 R2 F600\nX10\nX20\nX30\nX40\nX50\n"
      << "G98 G81 X50 Y10 Z-4 R1 F900\nX40\nX30\nX20\nX10\nX0\n"
      << "G99 G83 X0 Y20 Z-8 R2 Q2 F600\nX10\nX20\nX30\nX40\nX50\n"
      << "G98 G83 X50 Y30 Z-6 R2 Q1.5 F900\nX40\nX30\nX20\nX10\nX0\n"
      << "G99 G81 X0 Y40 Z-3 R1 F1200\nX10\nX20\nX30\nX40\nX50\n"
      << "G80 G0 Z10\nM2\n";
}

}  // namespace

fs::path write_cncd_ini(const fs::path& dir) {
  const fs::path path = dir / "bench_mill.ini";
  std::ofstream out(path);
  out << "# planner bench: a small fast mill, simulated drives\n"
         "[EMC]\nMACHINE = planner bench mill\n[EMCMOT]\nSERVO_PERIOD = 1000000\n"
         "[EMCIO]\nTOOL_TABLE = bench_mill.tbl\n"
         "[TRAJ]\nCOORDINATES = X Y Z\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n"
         "MAX_LINEAR_VELOCITY = "
      << kLinearVelocity << "\nMAX_LINEAR_ACCELERATION = " << kLinearAcceleration
      << "\n[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n";
  for (int i = 0; i < 3; ++i)
    out << axis_section("XYZ"[i], false, i);
  for (int i = 0; i < 3; ++i)
    out << axis_section("XYZ"[i], true, i);
  std::ofstream(dir / "bench_mill.tbl") << "T1 P1 Z0 D10 ;10 mm ball\n";
  return path;
}

fs::path write_linuxcnc_ini(const fs::path& dir, const fs::path& axis_mm_ini, std::string& error) {
  std::ifstream in(axis_mm_ini);
  if (!in) {
    error = "cannot read " + axis_mm_ini.string();
    return {};
  }
  // Line by line, as LinuxCNC INIs repeat keys: the limit keys of [TRAJ], [AXIS_*] and
  // [JOINT_*] take the bench machine's values; everything else stays.
  std::ostringstream out;
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '[') section = line.substr(0, line.find(']') + 1);
    const auto equals = line.find('=');
    std::string key = equals == std::string::npos ? "" : line.substr(0, equals);
    key.erase(key.find_last_not_of(" \t") + 1);
    const bool axis = section.rfind("[AXIS_", 0) == 0;
    const bool joint = section.rfind("[JOINT_", 0) == 0;
    const bool z = section == "[AXIS_Z]" || section == "[JOINT_2]";
    std::string value;
    if (section == "[TRAJ]" && (key == "MAX_LINEAR_VELOCITY" || key == "DEFAULT_LINEAR_VELOCITY"))
      value = number(kLinearVelocity);
    else if (section == "[TRAJ]" &&
             (key == "MAX_LINEAR_ACCELERATION" || key == "DEFAULT_LINEAR_ACCELERATION"))
      value = number(kLinearAcceleration);
    else if ((axis || joint) && key == "MAX_VELOCITY")
      value = number(z ? kZVelocity : kXyVelocity);
    else if ((axis || joint) && key == "MAX_ACCELERATION")
      value = number(z ? kZAcceleration : kXyAcceleration);
    else if ((axis || joint) && key == "MIN_LIMIT")
      value = number(z ? -kLimit / 2 : -kLimit);
    else if ((axis || joint) && key == "MAX_LIMIT")
      value = number(z ? kLimit / 2 : kLimit);
    else if (section == "[EMCMOT]" && key == "SERVO_PERIOD")
      value = "1000000";
    out << (value.empty() ? line : key + " = " + value) << "\n";
  }
  // Its tool table and parameter file are found next to it.
  std::error_code ec;
  for (const char* name : {"sim_mm.tbl", "sim_mm.var"}) {
    const fs::path source = axis_mm_ini.parent_path() / name;
    if (fs::exists(source, ec))
      fs::copy_file(source, dir / name, fs::copy_options::overwrite_existing, ec);
  }
  if (!fs::exists(dir / "sim_mm.tbl", ec))
    std::ofstream(dir / "sim_mm.tbl") << "T1 P1 Z0 D10 ;10 mm ball\n";
  const fs::path path = dir / "linuxcnc_mill.ini";
  std::ofstream(path) << out.str();
  return path;
}

std::vector<BenchProgram> write_programs(const fs::path& dir, const fs::path& chips_ngc) {
  std::vector<BenchProgram> programs;
  programs.push_back({"(a) raster F3000", dir / "raster_f3000.ngc"});
  write_raster(programs.back().path, 3000);
  programs.push_back({"(a) raster F6000", dir / "raster_f6000.ngc"});
  write_raster(programs.back().path, 6000);
  programs.push_back({"(b) circle F9000", dir / "circle_f9000.ngc"});
  write_circle(programs.back().path);
  programs.push_back({"(c) G81/G83 grid", dir / "drill_grid.ngc", true});
  write_drilling(programs.back().path);
  std::error_code ec;
  if (fs::exists(chips_ngc, ec)) programs.push_back({"(d) 3D_Chips.ngc", chips_ngc});
  return programs;
}

}  // namespace cncd::bench
