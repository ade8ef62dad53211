// Internal error signal: thrown while parsing or executing a block and turned into an
// InterpError (with file and line) by the Interpreter. Never escapes the library.
#pragma once

#include <string>
#include <utility>

namespace cncd::interp {

struct Failure {
  std::string message;
  int column = 0;  // 1-based column in the source line, 0 = whole line
};

[[noreturn]] inline void fail(std::string message, int column = 0) {
  throw Failure{std::move(message), column};
}

}  // namespace cncd::interp
