// Prints how many lines per second the interpreter runs: simple G1 lines from a file into a
// sink that ignores them. A benchmark, never a test.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

int main(int argc, char** argv) {
  const long lines = argc > 1 ? std::atol(argv[1]) : 1000000;
  const auto path = std::filesystem::temp_directory_path() / "cncd_interp_bench.ngc";
  {
    std::ofstream out(path);
    out << "G21 G90 G17 F1000\n";
    char line[96];
    for (long i = 0; i < lines; ++i) {
      std::snprintf(line, sizeof line, "G1 X%.3f Y%.3f Z%.3f\n", (i % 100) * 0.5,
                    ((i * 7) % 100) * 0.25, -(i % 10) * 0.1);
      out << line;
    }
    out << "M2\n";
  }
  cncd::interp::Interpreter interp;
  cncd::interp::NullSink sink;
  const auto start = std::chrono::steady_clock::now();
  auto error = interp.open(path);
  if (!error) error = cncd::interp::run_program(interp, sink);
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  std::filesystem::remove(path);
  if (error) {
    std::cerr << error->to_string() << '\n';
    return 1;
  }
  std::cout << lines << " lines in " << elapsed.count()
            << " s: " << static_cast<double>(lines) / elapsed.count() / 1e6 << " million lines/s\n";
  return 0;
}
