// Internal error signal: thrown while parsing or executing a block and turned into an
// InterpError (with file and line) by the Interpreter. Never escapes the library.
#pragma once

#include <string>
#include <utility>

namespace cncd::interp {

struct Failure {
  std::string message;
  int column = 0;  // 1-based column in the source line, 0 = whole line
  // Where, when not the line being executed (a line read ahead while seeking); line 0 = that
  // line.
  std::string file;
  int line = 0;
};

// A program or file value used as an integer (L, P, T, H, Q words, loop counts, tool table
// fields): truncated toward zero and clamped to +-2e9, so that a huge value fails the range
// check that follows instead of overflowing the conversion; NaN gives 0.
inline int to_int(double value) {
  if (value != value) return 0;
  if (value > 2e9) return 2'000'000'000;
  if (value < -2e9) return -2'000'000'000;
  return static_cast<int>(value);
}

[[noreturn]] inline void fail(std::string message, int column = 0) {
  throw Failure{std::move(message), column, {}, 0};
}

}  // namespace cncd::interp
