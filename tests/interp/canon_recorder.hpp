// A sink that keeps every canonical command the interpreter emits, for tests to look through
// by kind.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"

namespace cncd::interp::test_support {

struct CanonRecorder : CanonSink {
  void emit(const CanonCommand& command) override { commands.push_back(command); }
  // The operations of kind T, in order.
  template <class T>
  std::vector<T> all() const {
    std::vector<T> found;
    for (const auto& c : commands) {
      if (const auto* op = std::get_if<T>(&c.op)) found.push_back(*op);
    }
    return found;
  }
  // The messages of (MSG,...) and (DEBUG,...) comments, in order.
  std::vector<std::string> messages() const {
    std::vector<std::string> texts;
    for (const auto& m : all<Message>())
      texts.push_back(m.text);
    return texts;
  }
  std::vector<CanonCommand> commands;
};

}  // namespace cncd::interp::test_support
