// Checks a whole G-code program against a machine without moving it: runs it through the
// interpreter into a sink that converts every move to machine coordinates (MachineTracker) and
// tests it against the axis soft limits ([AXIS_<L>] MIN_LIMIT/MAX_LIMIT), arcs over their whole
// sweep. Used by cncd-check and by the daemon's program.open. Any thread; no shared state.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/pipeline/holes.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/modal_text.hpp"
#include "cncd/pipeline/preview.hpp"

namespace cncd::pipeline {

struct CheckProblem {
  std::string file;
  int line = 0;
  std::string message;
  // "FILE:LINE: message"
  std::string to_string() const;
};

struct CheckOptions {
  interp::InterpOptions interp;
  // The machine whose soft limits apply; null = no limit check.
  const config::MachineConfig* machine = nullptr;
  // Where the machine is when the program starts (machine coordinates and units); unset = the
  // interpreter's default (program zero).
  std::optional<interp::Pose> start_machine;
  // Limit problems kept in `problems`; further ones are only counted.
  std::size_t max_problems = 100;
  // The check stops after this long (0 = never) and says so in `stopped`: a program looping
  // forever with moves never ends.
  double max_seconds = 0;
  // max_seconds counts the processor time of the checking thread rather than wall time: a
  // check on a thread of low priority gets as far on a busy machine as on an idle one.
  bool max_seconds_cpu = false;
  // Set from another thread to stop the check early (program.open superseded or cancelled);
  // CheckReport::cancelled tells.
  const std::atomic<bool>* cancel = nullptr;
  // Also receives every canonical command as the interpreter emits it (cncd-check --canon).
  interp::CanonSink* trace = nullptr;
  // Collect the holes the program drills in CheckReport::holes (cncd-check --holes).
  bool find_holes = false;
  // Receives the path for display (cncd-check --preview, program.preview).
  PreviewBuilder* preview = nullptr;
  // Run from this line (> 1) as the daemon does (ProgramRunner::skip_to): only the moves from
  // the line on are checked, and CheckReport::from_line says what is rebuilt and done first.
  int from_line = 0;
};

struct CheckReport {
  bool limits_checked = false;
  std::size_t traverses = 0;  // G0 moves, canned-cycle rapids included
  std::size_t feeds = 0;      // straight feed moves
  std::size_t arcs = 0;
  std::size_t dwells = 0;
  std::size_t blocks = 0;  // blocks interpreted
  // Extents of the commanded path per axis, machine coordinates and units; an axis no move
  // reached keeps moved[axis] false.
  std::array<bool, interp::kAxes> moved{};
  interp::Pose min{};
  interp::Pose max{};
  std::set<int> tools;        // tools put in the spindle (M6, M61)
  double feed_length = 0;     // length of the feed moves (XYZ, machine units)
  bool inch_machine = false;  // machine units are inches (else mm)
  // The dialect the program was read in (Interpreter::dialect() once it was opened).
  interp::Dialect dialect = interp::Dialect::linuxcnc;
  // With CheckOptions::find_holes, in the order they are drilled.
  std::vector<Hole> holes;
  // The interpreter's error, when it stopped the program.
  std::optional<interp::InterpError> error;
  // Set when the check stopped before the end of the program (CheckOptions::max_seconds).
  std::optional<CheckProblem> stopped;
  bool cancelled = false;  // CheckOptions::cancel stopped it: the report is incomplete
  // Moves beyond a soft limit, in program order.
  std::vector<CheckProblem> problems;
  std::size_t limit_violations = 0;  // all of them, including those not kept
  // With CheckOptions::from_line.
  std::optional<FromLineReport> from_line;

  bool ok() const { return !error && !stopped && limit_violations == 0; }
};

// Runs `program` from start to end. Never writes the parameter file.
CheckReport check_program(const std::filesystem::path& program, const CheckOptions& options);

// Whether the first line of `program` names the dialect it is read in ("(dialect numeryx)"),
// rather than leaving it to InterpOptions::dialect. False when it cannot be opened.
bool names_its_dialect(const std::filesystem::path& program);

// The human summary cncd-check prints: moves by kind, extents per axis, tools, feed length.
std::string describe(const CheckReport& report);

// The holes of a report one per line under a header naming the coordinates and units:
// number, program line, X, Y, top, bottom.
std::string describe_holes(const CheckReport& report);

}  // namespace cncd::pipeline
