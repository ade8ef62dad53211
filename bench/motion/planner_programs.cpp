#include "planner_programs.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// Lines of a program, numbered as the interpreter numbers them (from 1).
struct Program {
  std::vector<std::string> lines;
  int add(std::string line) {
    lines.push_back(std::move(line));
    return static_cast<int>(lines.size());
  }
  void write(const fs::path& path) const {
    std::ofstream out(path);
    for (const auto& line : lines)
      out << line << "\n";
  }
};

constexpr const char* kModes = "G21 G17 G40 G49 G80 G90 G94 G54";

// Z over the surfacing raster, a gentle wave: z = -1 + 0.5 sin(2 pi x / 20) cos(2 pi y / 30).
// Along a row at F6000 (100 mm/s) Z moves at most 0.5 (2 pi / 20) 100 = 15.7 mm/s (limit 100)
// and accelerates at most 0.5 (2 pi / 20)^2 100^2 = 493 mm/s^2 (limit 1000); the path tilts at
// most atan(0.157) = 8.9 degrees from X, where X allows 200 / cos(8.9) mm/s. The blend arcs
// between the 0.1 mm chords have a radius of about 1 / curvature = 1 / 0.049 = 20 mm, whose
// speed limit in the XZ plane, sqrt(0.95 1000 20) = 138 mm/s, is above the feed: the limits
// allow the full feed all along the rows. At x = 0 and 100 z = -1 for every y: the step-overs
// move Y alone.
double surface_z(double x, double y) {
  return -1.0 +
         0.5 * std::sin(2 * std::numbers::pi * x / 20) * std::cos(2 * std::numbers::pi * y / 30);
}

// A raster along X over z(x, y): `rows` rows of `steps` G1 segments of `step`, `stepover`
// apart in Y, alternating in direction; the path is the rows and the step-overs between them.
struct Raster {
  int rows;
  int steps;
  double step;
  double stepover;
  double (*z)(double, double);
  int feed;
  std::string blend;  // the G64 line
  std::string title;
};

BenchProgram write_raster(const fs::path& path, const std::string& name, const Raster& r) {
  BenchProgram program{name, path};
  Program p;
  p.add("(planner bench: " + r.title + ", F" + std::to_string(r.feed) + ", " + r.blend + ")");
  p.add(kModes);
  program.prelude_lines = p.add(r.blend);
  p.add("G0 Z5");
  p.add("G0 X0 Y0");
  const std::string feed = " F" + std::to_string(r.feed);
  p.add("G1 Z" + number(r.z(0, 0)) + feed);
  for (int row = 0; row < r.rows; ++row) {
    const double y = r.stepover * row;
    if (row > 0) p.add("Y" + number(y) + " Z" + number(r.z(row % 2 ? r.steps * r.step : 0, y)));
    for (int k = 1; k <= r.steps; ++k) {
      const double x = r.step * (row % 2 ? r.steps - k : k);
      const std::string move = "X" + number(x) + " Z" + number(r.z(x, y));
      const int line = p.add(row == 0 && k == 1 ? "G1 " + move + feed : move);
      if (row == 0 && k == 1) program.path_first_line = line;
      program.path_last_line = line;
    }
  }
  p.add("G0 Z5");
  p.add("M2");
  p.write(path);
  return program;
}

// (a) 3D surfacing: 21 rows of 1000 G1 segments of 0.1 mm along X over a 100 x 10 mm patch,
// 0.5 mm step-over, over surface_z.
BenchProgram write_surfacing(const fs::path& path, const std::string& name, int feed,
                             const std::string& blend) {
  return write_raster(path, name,
                      {21, 1000, 0.1, 0.5, surface_z, feed, blend,
                       "3D surfacing raster, 100 x 10 mm, 21 rows of 0.1 mm G1 segments"});
}

// (e) 3D surface finishing as CAM writes it: 100 rows of 2000 G1 segments of 0.05 mm along X
// (200,000 lines) over a 100 x 29.7 mm patch, 0.3 mm step-over, coordinates to 4 decimals
// (their rounding turns every segment by up to 0.06 degrees), F6000 under G64 P0.01, over
// z = -3 + 1.5 sin(2 pi x / 40) cos(2 pi y / 25) + 0.4 sin(2 pi (x + 2 y) / 15). Its curvature
// needs up to (1.5 (2 pi / 40)^2 + 0.4 (2 pi / 15)^2) 100^2 = 1070 mm/s^2 of Z at the feed
// (limit 1000): in places the axes, not the feed, set the speed.
double finish_z(double x, double y) {
  const double two_pi = 2 * std::numbers::pi;
  return -3.0 + 1.5 * std::sin(two_pi * x / 40) * std::cos(two_pi * y / 25) +
         0.4 * std::sin(two_pi * (x + 2 * y) / 15);
}

BenchProgram write_finish(const fs::path& path) {
  return write_raster(path, "(e) 3D surface finish, 200,000 lines",
                      {100, 2000, 0.05, 0.3, finish_z, 6000, "G64 P0.01",
                       "3D surface finish, 100 rows of 2000 G1 segments of 0.05 mm"});
}

// The G64 P and Q in force after the program's first `lines` lines (0: none; Q is P when
// only P is given, as in LinuxCNC).
void blend_tolerances(BenchProgram& program) {
  std::ifstream in(program.path);
  int count = 0;
  const auto value = [](const std::string& text, std::size_t at, char letter) {
    const auto found = text.find(letter, at);
    return found == std::string::npos ? -1.0 : std::strtod(text.c_str() + found + 1, nullptr);
  };
  for (std::string line; count < program.prelude_lines && std::getline(in, line); ++count) {
    std::string text;
    for (char c : line)
      if (!std::isspace(static_cast<unsigned char>(c)))
        text += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    const auto g64 = text.find("G64");
    if (g64 == std::string::npos ||
        (g64 + 3 < text.size() && std::isdigit(static_cast<unsigned char>(text[g64 + 3]))))
      continue;
    const double p = value(text, g64 + 3, 'P');
    const double q = value(text, g64 + 3, 'Q');
    program.tolerance = std::max(0.0, p);
    program.merge_tolerance = q >= 0 ? q : program.tolerance;
  }
}

// (b) a circle of R30 mm in 0.1 mm chords at F9000, `laps` times round in one G1 chain, after
// a 30 mm rapid and a 1 mm plunge: the centripetal acceleration 150^2 / 30 = 750 mm/s^2 is
// well within 2000, so the limits allow the full feed all round.
BenchProgram write_circle(const fs::path& path, const std::string& name, int laps) {
  constexpr double kRadius = 30;
  const int chords = static_cast<int>(std::round(2 * std::numbers::pi * kRadius / 0.1));
  BenchProgram program{name, path};
  Program p;
  p.add("(planner bench: circle R30 of " + std::to_string(chords) + " chords of 0.1 mm, " +
        std::to_string(laps) + (laps == 1 ? " lap" : " laps") + ", F9000, G64)");
  p.add(kModes);
  program.prelude_lines = p.add("G64");
  p.add("G0 Z1");
  p.add("G0 X" + number(kRadius) + " Y0");
  p.add("G1 Z0 F9000");
  for (int i = 1; i <= chords * laps; ++i) {
    const double t = 2 * std::numbers::pi * (i % chords) / chords;
    const std::string move =
        "X" + number(kRadius * std::cos(t)) + " Y" + number(kRadius * std::sin(t));
    const int line = p.add(i == 1 ? "G1 " + move + " F9000" : move);
    if (i == 1) program.path_first_line = line;
    program.path_last_line = line;
  }
  p.add("G0 Z1");
  p.add("M2");
  p.write(path);
  return program;
}

// (c) a 6 x 5 grid: G81 rows (G99 and G98) and G83 peck rows.
void write_drilling(const fs::path& path) {
  std::ofstream out(path);
  out << "(planner bench: drilling grid, G81 and G83)\n"
      << kModes << "\nG0 Z10\nG0 X0 Y0\n"
      << "G99 G81 X0 Y0 Z-5 R2 F600\nX10\nX20\nX30\nX40\nX50\n"
      << "G98 G81 X50 Y10 Z-4 R1 F900\nX40\nX30\nX20\nX10\nX0\n"
      << "G99 G83 X0 Y20 Z-8 R2 Q2 F600\nX10\nX20\nX30\nX40\nX50\n"
      << "G98 G83 X50 Y30 Z-6 R2 Q1.5 F900\nX40\nX30\nX20\nX10\nX0\n"
      << "G99 G81 X0 Y40 Z-3 R1 F1200\nX10\nX20\nX30\nX40\nX50\n"
      << "G80 G0 Z10\nM2\n";
}

// (d) LinuxCNC's sample as it is; its dense path is the cut from N110 (after the plunge) to
// N6901 (before the retract), and the lines before N50 (the tool change) set its modes.
BenchProgram chips_program(const fs::path& chips_ngc) {
  BenchProgram program{"(d) 3D_Chips.ngc", chips_ngc};
  // The line's block number is `word` (N110, not N1100).
  const auto numbered = [](const std::string& line, const std::string& word) {
    return line.rfind(word, 0) == 0 &&
           (line.size() == word.size() ||
            !std::isdigit(static_cast<unsigned char>(line[word.size()])));
  };
  std::ifstream in(chips_ngc);
  int count = 0;
  for (std::string line; std::getline(in, line);) {
    ++count;
    if (numbered(line, "N50") && program.prelude_lines == 0) program.prelude_lines = count - 1;
    if (numbered(line, "N110")) program.path_first_line = count;
    if (numbered(line, "N6901")) program.path_last_line = count;
  }
  if (program.prelude_lines == 0 || program.path_first_line == 0 ||
      program.path_last_line < program.path_first_line)
    program.path_first_line = program.path_last_line = 0;
  return program;
}

}  // namespace

fs::path write_cncd_ini(const fs::path& dir) {
  const fs::path path = dir / "bench_mill.ini";
  std::ofstream out(path);
  out << "# planner bench: a small fast mill, simulated drives\n"
         "[EMC]\nMACHINE = planner bench mill\n[EMCMOT]\nSERVO_PERIOD = 1000000\n"
         // By its full path: a relative one names a file in the machine's state directory.
         "[EMCIO]\nTOOL_TABLE = "
      << (dir / "bench_mill.tbl").string()
      << "\n"
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
  programs.push_back(write_surfacing(dir / "raster_f3000.ngc", "(a) raster F3000", 3000, "G64"));
  programs.push_back(write_surfacing(dir / "raster_f6000.ngc", "(a) raster F6000", 6000, "G64"));
  programs.push_back(write_surfacing(dir / "raster_f6000_p005.ngc",
                                     "(a) raster F6000 under G64 P0.05", 6000, "G64 P0.05"));
  programs.push_back(write_circle(dir / "circle_f9000.ngc", "(b) circle F9000, 10 laps", 10));
  programs.push_back(write_circle(dir / "circle_f9000_1lap.ngc", "(b) circle F9000, 1 lap", 1));
  programs.push_back({"(c) G81/G83 grid", dir / "drill_grid.ngc", true});
  write_drilling(programs.back().path);
  std::error_code ec;
  if (fs::exists(chips_ngc, ec)) {
    programs.push_back(chips_program(chips_ngc));
    programs.back().diagnose = true;
  }
  programs.push_back(write_finish(dir / "surface_finish.ngc"));
  programs.back().diagnose = true;
  for (auto& program : programs)
    blend_tolerances(program);
  return programs;
}

fs::path write_path_alone(const BenchProgram& program, const fs::path& dir,
                          const motion::AxisPose& start) {
  std::ifstream in(program.path);
  const fs::path path = dir / (program.path.stem().string() + "_path.ngc");
  std::ofstream out(path);
  out << "(planner bench: the dense path of " << program.path.filename().string()
      << " alone, from rest where it starts)\n";
  int count = 0;
  bool ended = false;
  for (std::string line; std::getline(in, line);) {
    ++count;
    if (count == program.prelude_lines + 1)
      out << "G92 X" << number(start[0]) << " Y" << number(start[1]) << " Z" << number(start[2])
          << "\n";
    if (count <= program.prelude_lines ||
        (count >= program.path_first_line && count <= program.path_last_line))
      out << line << "\n";
    ended = count >= program.path_last_line;
  }
  out << "G92.1\nM2\n";
  if (!ended || !out) return {};
  return path;
}

}  // namespace cncd::bench
