// Prints canonical commands the way LinuxCNC's standalone `rs274` does (same names, argument
// order and number formats), without its leading counter and N-number columns. Used for golden
// tests against rs274 and by `cncd-check --canon`.
#pragma once

#include <ostream>
#include <string>

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

// One command as rs274 prints it, e.g. "STRAIGHT_FEED(1.0000, 2.0000, 0.0000, 0.0000, 0.0000,
// 0.0000)". `axes` = 6 prints X Y Z A B C (rs274 without an INI file), 9 adds U V W. Empty for
// a command rs274 does not print (WaitInput: its WAIT is silent); the printer leaves out its
// line. UserMCode, which rs274 never gets to (it knows no user M codes), prints as
// USER_M_CODE(code, p, q).
std::string format_rs274(const CanonCommand& command, int axes = 6);

class Rs274Printer final : public CanonSink {
 public:
  explicit Rs274Printer(std::ostream& out, int axes = 6) : out_(out), axes_(axes) {}
  void emit(const CanonCommand& command) override;

 private:
  std::ostream& out_;
  int axes_;
  std::string buffer_;
};

// A sink that ignores everything (benchmarks, syntax checks).
class NullSink final : public CanonSink {
 public:
  void emit(const CanonCommand&) override {}
};

}  // namespace cncd::interp
