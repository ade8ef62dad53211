// What the Numeryx dialect tests run programs through: a recorder of the canonical commands,
// the holes a program drills (found in its moves), and short ways to the moves or the error of
// a program read as Numeryx.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp::numeryx_test {

class Recorder final : public CanonSink {
 public:
  void emit(const CanonCommand& command) override {
    if (std::holds_alternative<StraightTraverse>(command.op) ||
        std::holds_alternative<StraightFeed>(command.op) ||
        std::holds_alternative<Dwell>(command.op)) {
      moves.push_back(format_rs274(command, 3));
    }
    all.push_back(format_rs274(command));
    ops.push_back(command.op);
  }
  std::vector<std::string> moves;
  std::vector<std::string> all;
  std::vector<CanonOp> ops;
};

struct Outcome {
  Recorder recorder;
  std::optional<InterpError> error;
  Dialect dialect = Dialect::linuxcnc;
};

inline Outcome run(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(std::move(options));
  Outcome result;
  result.error = interp.open_string(program, "nx.ngc");
  result.dialect = interp.dialect();
  if (!result.error) result.error = run_program(interp, result.recorder);
  return result;
}

inline std::vector<std::string> moves(const std::string& program, InterpOptions options = {}) {
  Outcome r = run("(dialect numeryx)\n" + program, std::move(options));
  EXPECT_FALSE(r.error) << (r.error ? r.error->to_string() : "");
  return r.recorder.moves;
}

inline std::string error_of(const std::string& program) {
  Outcome r = run("(dialect numeryx)\n" + program);
  return r.error ? r.error->to_string() : "no error";
}

// A hole: a feed straight down at one XY; its top is where the feed starts, its bottom the
// lowest Z reached there, and `retract` the Z the tool leaves the hole at.
struct Hole {
  double x = 0;
  double y = 0;
  double top = 0;
  double bottom = 0;
  double retract = 0;
};

inline std::vector<Hole> holes(const std::vector<CanonOp>& ops) {
  std::vector<Hole> out;
  Pose at{};
  bool in_hole = false;
  for (const auto& op : ops) {
    const Pose* end = nullptr;
    bool feed = false;
    if (const auto* t = std::get_if<StraightTraverse>(&op)) end = &t->end;
    if (const auto* f = std::get_if<StraightFeed>(&op)) {
      end = &f->end;
      feed = true;
    }
    if (end == nullptr) continue;
    const bool same_xy = (*end)[0] == at[0] && (*end)[1] == at[1];
    if (!same_xy) in_hole = false;
    if (feed && same_xy && (*end)[2] < at[2]) {
      if (!in_hole) out.push_back(Hole{at[0], at[1], at[2], (*end)[2], (*end)[2]});
      in_hole = true;
      out.back().bottom = std::min(out.back().bottom, (*end)[2]);
    }
    if (in_hole) out.back().retract = (*end)[2];
    at = *end;
  }
  return out;
}

inline std::vector<Hole> holes_of(const std::string& program, InterpOptions options = {}) {
  Outcome r = run("(dialect numeryx)\n" + program, std::move(options));
  EXPECT_FALSE(r.error) << (r.error ? r.error->to_string() : "");
  return holes(r.recorder.ops);
}

inline void expect_hole(const Hole& h, double x, double y, double top, double bottom,
                        double retract) {
  EXPECT_NEAR(h.x, x, 1e-9);
  EXPECT_NEAR(h.y, y, 1e-9);
  EXPECT_NEAR(h.top, top, 1e-9);
  EXPECT_NEAR(h.bottom, bottom, 1e-9);
  EXPECT_NEAR(h.retract, retract, 1e-9);
}

// --- cycle heights ------------------------------------------------------------------------

}  // namespace cncd::interp::numeryx_test
