// cncd-check: runs a G-code program through the interpreter without a machine. By default it
// checks the program against the machine in the INI (interpreter errors, every move within the
// axis soft limits) and prints a summary; --canon prints the canonical commands the way
// LinuxCNC's rs274 does instead, --holes the holes the program drills; --plan runs the program
// through the planner and the servo loop in virtual time and prints the cycle time and what
// the motion would be like (plan_sim). Problems go to stderr as FILE:LINE: message.
//
//   cncd-check [--ini FILE] [--canon | --holes] [--dialect linuxcnc|numeryx] [--inch]
//              [--tool-units mm|inch] [-t TOOL.tbl] [-v PARAMS.var] [--max-seconds S] PROGRAM
//   cncd-check --plan [--json] [--trajectory FILE.csv] --ini FILE [...] PROGRAM
//
// Exit status: 0 good, 1 program problems, 2 usage, 78 invalid INI.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "cncd/pipeline/program_check.hpp"
#include "cncd/pipeline/program_preview.hpp"
#include "cncd/pipeline/startup_code.hpp"

namespace {

constexpr int kExitProblems = 1;
constexpr int kExitUsage = 2;

int usage(const std::string& why) {
  if (!why.empty()) std::cerr << "cncd-check: " << why << '\n';
  std::cerr
      << "usage: cncd-check [--ini FILE [--state-dir DIR]] [--canon | --holes] [--inch]\n"
         "                  [--dialect linuxcnc|numeryx] [--tool-units mm|inch]\n"
         "                  [-t TOOL.tbl] [-v PARAMS.var] [--max-seconds S] PROGRAM.ngc\n"
         "       cncd-check --plan [--json] [--trajectory FILE.csv] --ini FILE [...] PROGRAM.ngc\n"
         "       cncd-check --preview [--tolerance T] [--ini FILE ...] PROGRAM.ngc\n"
         "       cncd-check --from-line N [--plan] --ini FILE [...] PROGRAM.ngc\n"
         "  --ini FILE   take units, tool table, parameter file (read only), subroutine path,\n"
         "               start-up code and the axis soft limits from the machine's INI\n"
         "  --state-dir DIR  where the machine's parameter file and tool table live\n"
         "               (default as for cncd: [CNCD] STATE_DIR, $STATE_DIRECTORY,\n"
         "               $XDG_STATE_HOME/cncd/<INI name>); read only, never written\n"
         "  --canon      print the canonical commands as LinuxCNC's rs274 does\n"
         "  --holes      print the holes the program drills instead of the summary: number,\n"
         "               line, X, Y, top and bottom (machine coordinates and units)\n"
         "  --dialect D  read the program as linuxcnc or numeryx, whatever its first line\n"
         "               and [RS274NGC] DIALECT say\n"
         "  --inch       machine units are inches (without --ini)\n"
         "  --tool-units units the tool table is written in (default: the machine's)\n"
         "  -t, -v       tool table and parameter file (without --ini, or to override it)\n"
         "  --max-seconds S  stop checking after S seconds (default 600, 0 = never)\n"
         "  --plan       run the planner and servo loop in virtual time: cycle time, its\n"
         "               feed-limited and exact-stop bounds, peak axis velocity and\n"
         "               acceleration (beside them the joints', where the kinematics is not\n"
         "               trivkins), largest deviation from the programmed path\n"
         "  --json       with --plan: print one JSON object instead\n"
         "  --preview    print the toolpath as program.preview answers it (one JSON object):\n"
         "               extents and polylines in machine coordinates, tagged with lines\n"
         "  --tolerance T  with --preview: how far the drawn path may pass from a point it\n"
         "               leaves out, machine units (default 0.01 mm, 0.0004 in)\n"
         "  --trajectory FILE.csv  with --plan: write t, every axis, the spindle's\n"
         "               position (revolutions) and every joint (j0 ...) per servo period;\n"
         "               with TCP also the tool tip in the part's frame (tip_x ...) and tcp\n"
         "  --from-line N  run from line N as cncd does: check (or plan) from there on, and\n"
         "               print the state the lines before it leave and what is done before\n"
         "               it (tool, spindle, coolant, Z up, over the start, Z down) with\n"
         "               the machine at program zero\n"
         "exit status: 0 good, 1 program problems, 2 usage, 78 invalid INI\n";
  return kExitUsage;
}

// Writes the commanded trajectory to `path` through a temporary file renamed into place at
// the end, so that a reader never sees half of it: t, the axes (machine coordinates), the
// spindle, the joints (j0 ...), and on a machine with TCP the tool tip in the part's frame
// (tip_x ...) and whether the motion runs under TCP (tcp, 1 or 0).
class TrajectoryFile {
 public:
  TrajectoryFile(const std::string& path, const cncd::config::MachineConfig& machine)
      : path_(path),
        temp_(path + ".tmp." + std::to_string(::getpid())),
        out_(temp_),
        joints_(std::min<std::size_t>(machine.joints.size(), cncd::motion::kJoints)),
        tcp_(cncd::motion::make_kinematics(machine)->has_tcp()) {
    out_ << 't';
    for (std::size_t i = 0; i < cncd::config::kAxisLetters.size(); ++i) {
      if (machine.axes[i].present) axes_.push_back(i);
    }
    for (const std::size_t i : axes_)
      out_ << ',' << letter(i);
    out_ << ",spindle";
    for (std::size_t j = 0; j < joints_; ++j)
      out_ << ",j" << j;
    if (tcp_) {
      for (const std::size_t i : axes_)
        out_ << ",tip_" << letter(i);
      out_ << ",tcp";
    }
    out_ << '\n';
  }
  bool opened() const { return static_cast<bool>(out_); }
  void add(const cncd::pipeline::PlanSample& sample) {
    number(sample.t, false);
    for (const std::size_t i : axes_)
      number(sample.axes[i]);
    number(sample.spindle);
    for (std::size_t j = 0; j < joints_; ++j)
      number(sample.joints[j]);
    if (tcp_) {
      for (const std::size_t i : axes_)
        number(sample.tip[i]);
      out_ << (sample.tcp ? ",1" : ",0");
    }
    out_ << '\n';
  }
  // "" or what went wrong; the temporary file is removed on failure.
  std::string finish() {
    out_.flush();
    const bool written = static_cast<bool>(out_);
    out_.close();
    std::error_code ec;
    if (written) std::filesystem::rename(temp_, path_, ec);
    if (!written || ec) {
      std::filesystem::remove(temp_, ec);
      return "cannot write " + path_ + (written ? ": " + ec.message() : "");
    }
    return "";
  }

 private:
  static char letter(std::size_t axis) {
    return static_cast<char>(cncd::config::kAxisLetters[axis] - 'A' + 'a');
  }
  void number(double value, bool comma = true) {
    char text[40];
    std::snprintf(text, sizeof text, comma ? ",%.6f" : "%.6f", value);
    out_ << text;
  }

  std::string path_;
  std::string temp_;
  std::ofstream out_;
  std::vector<std::size_t> axes_;
  std::size_t joints_;
  bool tcp_;
};

// What chose the dialect a program was read in, for the summary.
std::string dialect_origin(const cncd::interp::InterpOptions& options, bool machine,
                           const std::string& program) {
  if (!options.dialect_from_first_line) return "--dialect";
  if (cncd::pipeline::names_its_dialect(program)) return "the program's first line";
  return machine ? "[RS274NGC] DIALECT" : "default";
}

int check_plan(const cncd::config::MachineConfig& machine, const std::string& program,
               cncd::pipeline::PlanSimOptions options, bool json, const std::string& trajectory) {
  std::unique_ptr<TrajectoryFile> csv;
  if (!trajectory.empty()) {
    csv = std::make_unique<TrajectoryFile>(trajectory, machine);
    if (!csv->opened()) {
      std::cerr << "cncd-check: cannot write " << trajectory << ": " << std::strerror(errno)
                << '\n';
      return kExitProblems;
    }
    options.on_period = [&csv](const cncd::pipeline::PlanSample& sample) { csv->add(sample); };
  }
  const auto result = cncd::pipeline::simulate_plan(machine, program, options);
  // A program that stopped before it moved has no figures worth a report (JSON always has one).
  if (json) {
    std::cout << cncd::pipeline::plan_json(machine, result) << '\n';
  } else if (result.complete() || result.cycles > 0) {
    std::cout << cncd::pipeline::describe_plan(machine, result);
  }
  std::cout.flush();
  bool ok = result.complete();
  if (result.error) std::cerr << result.error->to_string() << '\n';
  if (result.stopped) std::cerr << result.stopped->to_string() << '\n';
  if (csv) {
    if (const auto problem = csv->finish(); !problem.empty()) {
      std::cerr << "cncd-check: " << problem << '\n';
      ok = false;
    }
  }
  return ok ? 0 : kExitProblems;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cncd;
  interp::InterpOptions overrides;
  bool inch = false;
  bool canon = false;
  bool holes = false;
  std::optional<interp::Dialect> dialect;
  bool plan = false;
  bool json = false;
  bool preview = false;
  std::optional<double> tolerance;
  std::string trajectory;
  std::string ini;
  config::LoadOptions load_options;
  std::string program;
  double max_seconds = 600;
  int from_line = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--canon") {
      canon = true;
    } else if (arg == "--holes") {
      holes = true;
    } else if (arg == "--plan") {
      plan = true;
    } else if (arg == "--preview") {
      preview = true;
    } else if (arg == "--json") {
      json = true;
    } else if (arg == "--inch") {
      inch = true;
    } else if (arg == "--ini" || arg == "--tool-units" || arg == "-t" || arg == "-v" ||
               arg == "--max-seconds" || arg == "--trajectory" || arg == "--state-dir" ||
               arg == "--dialect" || arg == "--tolerance" || arg == "--from-line") {
      if (!has_value) return usage(arg + " needs a value");
      const std::string value = argv[++i];
      if (arg == "--ini") {
        ini = value;
      } else if (arg == "--state-dir") {
        load_options.state_dir = value;
      } else if (arg == "--trajectory") {
        trajectory = value;
      } else if (arg == "--dialect") {
        dialect = interp::parse_dialect(value);
        if (!dialect) return usage("--dialect must be linuxcnc or numeryx");
      } else if (arg == "--tolerance") {
        char* end = nullptr;
        tolerance = std::strtod(value.c_str(), &end);
        if (*end != '\0' || !(*tolerance > 0) || !std::isfinite(*tolerance))
          return usage("--tolerance needs a number above 0");
      } else if (arg == "--from-line") {
        char* end = nullptr;
        const long line = std::strtol(value.c_str(), &end, 10);
        if (*end != '\0' || value.empty() || line < 1 || line > 1'000'000'000)
          return usage("--from-line needs a line number from 1 on");
        from_line = static_cast<int>(line);
      } else if (arg == "--max-seconds") {
        char* end = nullptr;
        max_seconds = std::strtod(value.c_str(), &end);
        if (*end != '\0' || !(max_seconds >= 0)) return usage("--max-seconds needs a number");
      } else if (arg == "--tool-units") {
        if (value != "mm" && value != "inch") return usage("--tool-units must be mm or inch");
        overrides.tool_table_units = value == "mm" ? interp::Units::mm : interp::Units::inches;
      } else {
        (arg == "-t" ? overrides.tool_table : overrides.parameter_file) = value;
      }
    } else if (arg == "-h" || arg == "--help") {
      usage("");
      return 0;
    } else if (!arg.empty() && arg[0] != '-' && program.empty()) {
      program = arg;
    } else {
      return usage(program.empty() || arg[0] == '-' ? "unknown option '" + arg + "'"
                                                    : "only one program may be given");
    }
  }
  if (program.empty()) return usage("no program given");
  if (plan && ini.empty()) return usage("--plan needs --ini: the machine's limits");
  if (ini.empty() && !load_options.state_dir.empty()) return usage("--state-dir goes with --ini");
  if (plan && canon) return usage("--plan and --canon exclude each other");
  if (holes && (plan || canon)) return usage("--holes goes without --plan and --canon");
  if (!plan && (json || !trajectory.empty()))
    return usage("--json and --trajectory go with --plan");
  if (preview && (plan || canon || holes))
    return usage("--preview goes without --plan, --canon and --holes");
  if (tolerance && !preview) return usage("--tolerance goes with --preview");
  if (from_line > 0 && (canon || holes || preview))
    return usage("--from-line goes without --canon, --holes and --preview");

  pipeline::CheckOptions options;
  options.max_seconds = max_seconds;
  std::optional<config::LoadResult> loaded;
  if (!ini.empty()) {
    loaded = config::load_machine_config(ini, load_options);
    if (!loaded->ok()) {
      for (const auto& problem : loaded->problems)
        std::cerr << problem.to_string() << '\n';
      std::cerr << "cncd-check: " << loaded->problems.size() << " problem"
                << (loaded->problems.size() == 1 ? "" : "s") << " in " << ini << '\n';
      return config::kExitConfig;
    }
    // Every program starts with the machine's start-up code: a broken one fails them all.
    if (const auto problems = pipeline::check_startup_code(*loaded->config); !problems.empty()) {
      for (const auto& problem : problems)
        std::cerr << problem.to_string() << '\n';
      std::cerr << "cncd-check: " << problems.size() << " problem"
                << (problems.size() == 1 ? "" : "s") << " in " << ini << '\n';
      return config::kExitConfig;
    }
    options.machine = &*loaded->config;
    options.interp = pipeline::interpreter_options(*loaded->config);
    // Where the daemon would read them: the state directory's copies, else the seeds beside
    // the INI that it would start from. Only read; cncd-check never writes them.
    const auto& machine = *loaded->config;
    options.interp.parameter_file =
        config::state_file_to_read(machine.parameter_file, machine.parameter_file_seed);
    options.interp.tool_table =
        config::state_file_to_read(machine.tool_table, machine.tool_table_seed);
  } else if (inch) {
    options.interp.machine_units = interp::Units::inches;
  }
  if (!overrides.tool_table.empty()) options.interp.tool_table = overrides.tool_table;
  if (!overrides.parameter_file.empty()) options.interp.parameter_file = overrides.parameter_file;
  if (overrides.tool_table_units) options.interp.tool_table_units = overrides.tool_table_units;
  if (dialect) {
    options.interp.dialect = *dialect;
    options.interp.dialect_from_first_line = false;
  }
  // A parameter file or tool table not there yet is no reason to refuse: the daemon starts
  // from the defaults too, and writes the file later.
  const interp::Interpreter loader(options.interp);
  for (const auto& warning : loader.load_warnings())
    std::cerr << "cncd-check: warning: " << warning << '\n';

  std::ios::sync_with_stdio(false);
  if (plan) {
    pipeline::PlanSimOptions plan_options;
    plan_options.interp = options.interp;
    plan_options.max_wall_s = max_seconds;
    plan_options.from_line = from_line;
    return check_plan(*loaded->config, program, plan_options, json, trajectory);
  }
  if (preview) {
    pipeline::PreviewOptions preview_options;
    preview_options.tolerance = tolerance.value_or(
        pipeline::default_preview_tolerance(options.interp.machine_units == interp::Units::inches));
    const auto result = pipeline::preview_program(program, options, preview_options);
    if (result.report.blocks > 0 || !result.report.error)
      std::cout << pipeline::preview_json(result).dump() << '\n';
    std::cout.flush();
    if (result.report.error) std::cerr << result.report.error->to_string() << '\n';
    if (result.report.stopped) std::cerr << result.report.stopped->to_string() << '\n';
    for (const auto& problem : result.report.problems)
      std::cerr << problem.to_string() << '\n';
    return result.report.ok() ? 0 : kExitProblems;
  }
  interp::Rs274Printer printer(std::cout);
  if (canon) options.trace = &printer;
  options.find_holes = holes;
  options.from_line = from_line;
  const pipeline::CheckReport report = pipeline::check_program(program, options);
  // A program that could not even be opened has nothing to summarise.
  if (!canon && (report.blocks > 0 || !report.error)) {
    if (holes) {
      std::cout << pipeline::describe_holes(report);
    } else {
      std::cout << "dialect: " << interp::dialect_name(report.dialect) << " ("
                << dialect_origin(options.interp, !ini.empty(), program) << ")\n"
                << pipeline::describe(report);
      if (report.from_line)
        std::cout << pipeline::describe_from_line(*report.from_line, report.inch_machine);
    }
  }
  std::cout.flush();
  for (const auto& problem : report.problems)
    std::cerr << problem.to_string() << '\n';
  if (report.limit_violations > report.problems.size()) {
    std::cerr << "cncd-check: " << report.limit_violations - report.problems.size()
              << " more limit violations not shown\n";
  }
  if (report.error) std::cerr << report.error->to_string() << '\n';
  if (report.stopped) std::cerr << report.stopped->to_string() << '\n';
  return report.ok() ? 0 : kExitProblems;
}
