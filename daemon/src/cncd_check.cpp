// cncd-check: runs a G-code program through the interpreter without a machine and reports the
// first error as FILE:LINE:COLUMN: message (exit status 1), or prints the canonical commands.
//
//   cncd-check [--canon] [--inch] [--tool-units mm|inch] [-t TOOL.tbl] [-v PARAMS.var] PROGRAM
//
// --canon prints every canonical command the way LinuxCNC's rs274 does; --inch makes the
// machine's units inches; --tool-units says what units the tool table is written in.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace {

int usage() {
  std::cerr << "usage: cncd-check [--canon] [--inch] [--tool-units mm|inch] [-t TOOL.tbl] "
               "[-v PARAMS.var] PROGRAM.ngc\n";
  return 64;  // EX_USAGE
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cncd::interp;
  InterpOptions options;
  bool canon = false;
  std::string program;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--canon") {
      canon = true;
    } else if (arg == "--inch") {
      options.machine_units = Units::inches;
    } else if (arg == "--tool-units" && i + 1 < argc) {
      const std::string units = argv[++i];
      if (units != "mm" && units != "inch") return usage();
      options.tool_table_units = units == "mm" ? Units::mm : Units::inches;
    } else if ((arg == "-t" || arg == "-v") && i + 1 < argc) {
      (arg == "-t" ? options.tool_table : options.parameter_file) = argv[++i];
    } else if (!arg.empty() && arg[0] != '-' && program.empty()) {
      program = arg;
    } else {
      return usage();
    }
  }
  if (program.empty()) return usage();
  Interpreter interp(options);
  std::ios::sync_with_stdio(false);
  Rs274Printer printer(std::cout);
  NullSink null_sink;
  CanonSink& sink = canon ? static_cast<CanonSink&>(printer) : null_sink;
  auto error = interp.open(program);
  if (!error) error = run_program(interp, sink);
  std::cout.flush();
  if (error) {
    std::cerr << error->to_string() << '\n';
    return 1;
  }
  return 0;
}
