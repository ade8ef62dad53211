// cncd-check: runs a G-code program through the interpreter without a machine. By default it
// checks the program against the machine in the INI (interpreter errors, every move within the
// axis soft limits) and prints a summary; --canon prints the canonical commands the way
// LinuxCNC's rs274 does instead. Problems go to stderr as FILE:LINE: message.
//
//   cncd-check [--ini FILE] [--canon] [--inch] [--tool-units mm|inch] [-t TOOL.tbl]
//              [-v PARAMS.var] [--max-seconds S] PROGRAM
//
// Exit status: 0 good, 1 program problems, 2 usage, 78 invalid INI.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "program_check.hpp"

namespace {

constexpr int kExitProblems = 1;
constexpr int kExitUsage = 2;

int usage(const std::string& why) {
  if (!why.empty()) std::cerr << "cncd-check: " << why << '\n';
  std::cerr
      << "usage: cncd-check [--ini FILE] [--canon] [--inch] [--tool-units mm|inch]\n"
         "                  [-t TOOL.tbl] [-v PARAMS.var] [--max-seconds S] PROGRAM.ngc\n"
         "  --ini FILE   take units, tool table, parameter file (read only), subroutine path,\n"
         "               start-up code and the axis soft limits from the machine's INI\n"
         "  --canon      print the canonical commands as LinuxCNC's rs274 does\n"
         "  --inch       machine units are inches (without --ini)\n"
         "  --tool-units units the tool table is written in (default: the machine's)\n"
         "  -t, -v       tool table and parameter file (without --ini, or to override it)\n"
         "  --max-seconds S  stop checking after S seconds (default 600, 0 = never)\n"
         "exit status: 0 good, 1 program problems, 2 usage, 78 invalid INI\n";
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cncd;
  interp::InterpOptions overrides;
  bool inch = false;
  bool canon = false;
  std::string ini;
  std::string program;
  double max_seconds = 600;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--canon") {
      canon = true;
    } else if (arg == "--inch") {
      inch = true;
    } else if (arg == "--ini" || arg == "--tool-units" || arg == "-t" || arg == "-v" ||
               arg == "--max-seconds") {
      if (!has_value) return usage(arg + " needs a value");
      const std::string value = argv[++i];
      if (arg == "--ini") {
        ini = value;
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

  daemon::CheckOptions options;
  options.max_seconds = max_seconds;
  std::optional<config::LoadResult> loaded;
  if (!ini.empty()) {
    loaded = config::load_machine_config(ini);
    if (!loaded->ok()) {
      for (const auto& problem : loaded->problems)
        std::cerr << problem.to_string() << '\n';
      std::cerr << "cncd-check: " << loaded->problems.size() << " problem"
                << (loaded->problems.size() == 1 ? "" : "s") << " in " << ini << '\n';
      return config::kExitConfig;
    }
    options.machine = &*loaded->config;
    options.interp = daemon::interpreter_options(*loaded->config);
  } else if (inch) {
    options.interp.machine_units = interp::Units::inches;
  }
  if (!overrides.tool_table.empty()) options.interp.tool_table = overrides.tool_table;
  if (!overrides.parameter_file.empty()) options.interp.parameter_file = overrides.parameter_file;
  if (overrides.tool_table_units) options.interp.tool_table_units = overrides.tool_table_units;

  std::ios::sync_with_stdio(false);
  interp::Rs274Printer printer(std::cout);
  if (canon) options.trace = &printer;
  const daemon::CheckReport report = daemon::check_program(program, options);
  // A program that could not even be opened has nothing to summarise.
  if (!canon && (report.blocks > 0 || !report.error)) std::cout << daemon::describe(report);
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
