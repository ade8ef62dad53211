#include "cncd/pipeline/program_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string_view>
#include <variant>

#include "cncd/motion/planner.hpp"
#include "cncd/motion/soft_limits.hpp"
#include "cncd/pipeline/program_runner.hpp"
#include "number_text.hpp"

namespace cncd::pipeline {

using interp::CanonCommand;
using interp::kAxes;
using interp::Pose;

namespace {

double xyz_distance(const Pose& a, const Pose& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Without a machine, arcs are still built as the planner builds them, on a machine that has
// every axis (the soft limits are not checked then).
config::MachineConfig every_axis(interp::Units units) {
  config::MachineConfig machine;
  machine.linear_units =
      units == interp::Units::inches ? config::LinearUnits::inch : config::LinearUnits::mm;
  for (auto& axis : machine.axes)
    axis.present = true;
  return machine;
}

// Reads the program as the daemon's task does: ProgramRunner takes the canonical commands
// through the same feeder into machine moves, which come here, and an arc is the planner's own
// segment, so its reach is judged on the geometry the machine will follow. Every canonical
// command is seen here first (emit), for the trace and the counts.
class CheckSink final : public interp::CanonSink, public motion::MoveQueue {
 public:
  CheckSink(const CheckOptions& options, CheckReport& report, std::string file)
      : options_(options),
        report_(report),
        file_(std::move(file)),
        machine_(options.machine ? *options.machine : every_axis(options.interp.machine_units)),
        planner_(machine_) {}

  const config::MachineConfig& machine() const { return machine_; }
  // The runner's feeder, whose offsets place a program's first move.
  void follow(const ProgramFeeder& feeder) { feeder_ = &feeder; }

  // What stops the program besides the interpreter: a spindle the machine lacks.
  std::optional<interp::InterpError> stops_it;

  // With CheckOptions::find_holes, the holes so far.
  const std::vector<Hole>& holes() const { return holes_.holes(); }

  void start_at(const Pose& machine) { position_ = machine; }

  void emit(const CanonCommand& command) override {
    if (options_.trace) options_.trace->emit(command);
    auto tool = [&](int number) {
      if (number > 0) report_.tools.insert(number);
    };
    std::visit(interp::Overloaded{
                   [&](const interp::Dwell&) { ++report_.dwells; },
                   [&](const interp::ChangeTool& c) { tool(c.tool); },
                   [&](const interp::ChangeToolNumber& c) { tool(c.tool); },
                   [](const auto&) {},
               },
               command.op);
  }

  // Run from line: the moves of the block that reaches the line, its lead-in first.
  std::vector<motion::Move>* record = nullptr;

  Push push_move(const motion::Move& move) override {
    if (record != nullptr) record->push_back(move);
    switch (move.kind) {
      case motion::Move::Kind::traverse:
      case motion::Move::Kind::feed:
        line(move);
        break;
      case motion::Move::Kind::arc:
        arc(move);
        break;
      case motion::Move::Kind::dwell:
        break;
      case motion::Move::Kind::action:
        if (move.action.kind == motion::IoAction::Kind::spindle && move.action.direction != 0 &&
            machine_.spindle.driver == config::SpindleDriver::none && !stops_it) {
          stops_it = interp::InterpError{
              file_, move.line, 0,
              std::string(move.action.direction > 0 ? "M3" : "M4") +
                  " starts a spindle the machine does not have ([SPINDLE_0] DRIVER = none)"};
        }
        break;
    }
    return Push::accepted;
  }
  // Nothing is held back for look-ahead here, and nothing is refused.
  void end_path() override {}
  std::string refusal() const override { return {}; }

 private:
  void line(const motion::Move& move) {
    ensure_start();
    const bool feed = move.kind == motion::Move::Kind::feed;
    // A probing move feeds toward the work without cutting: no hole.
    if (options_.find_holes)
      holes_.straight(position_, move.end, feed && move.probe == motion::ProbeMode::none,
                      move.line);
    ++(feed ? report_.feeds : report_.traverses);
    if (options_.preview != nullptr) {
      const PieceKind kind = move.probe != motion::ProbeMode::none ? PieceKind::probe
                             : feed                                ? PieceKind::feed
                                                                   : PieceKind::rapid;
      options_.preview->move(kind, position_, move.end, move.line);
    }
    if (feed) report_.feed_length += xyz_distance(position_, move.end);
    reach(move.end, move.line, feed ? "feed move" : "rapid move");
    check_joints(move, feed ? "feed move" : "rapid move");
    position_ = move.end;
  }

  // Under TCP the joints follow the tool tip: each within its [JOINT_n] soft limits over the
  // whole path, as the planner checks it (one report per line).
  void check_joints(const motion::Move& move, const char* what) {
    std::string error;
    if (planner_.tcp_joints_within_limits(move, position_, error)) return;
    if (first_report(move.line, kAxes + 1, false))
      report_.problems.push_back({file_, move.line, std::string(what) + ": " + error});
  }

  // A straight move is checked at its end: the limits form a box and the move starts inside
  // it (or was reported when it got out). Until an axis leaves where it started it has not
  // been moved: the start is not a target of the program.
  void reach(const Pose& point, int line, const char* what) {
    for (std::size_t axis = 0; axis < kAxes; ++axis) {
      if (!left_start_[axis]) {
        if (std::abs(point[axis] - start_[axis]) <= 1e-9) continue;
        left_start_[axis] = true;
      }
      extend(axis, point[axis]);
      // An axis the move leaves where it was has been checked already.
      if (point[axis] != position_[axis]) check(axis, point[axis], line, what);
    }
  }

  // Where the first move starts: the given machine position, else program zero.
  void ensure_start() {
    if (started_) return;
    started_ = true;
    if (!options_.start_machine && feeder_ != nullptr)
      position_ = feeder_->tracker().machine_pose(Pose{});
    start_ = position_;
  }

  void extend(std::size_t axis, double value) {
    if (!report_.moved[axis]) {
      report_.moved[axis] = true;
      report_.min[axis] = report_.max[axis] = value;
    } else {
      report_.min[axis] = std::min(report_.min[axis], value);
      report_.max[axis] = std::max(report_.max[axis], value);
    }
  }

  bool limited(std::size_t axis) const {
    return options_.machine != nullptr &&
           options_.machine->coordinates.find(config::kAxisLetters[axis]) != std::string::npos;
  }

  void check(std::size_t axis, double value, int line, const char* what) {
    if (!limited(axis)) return;
    const char letter = config::kAxisLetters[axis];
    const config::AxisConfig& limits = options_.machine->axes[axis];
    const bool finite = std::isfinite(value);
    const bool below = value < limits.min_limit - motion::kSoftLimitSlack;
    const bool above = value > limits.max_limit + motion::kSoftLimitSlack;
    if (finite && !below && !above) return;
    if (!first_report(line, axis, above)) return;
    std::string message =
        !finite
            ? std::string(what) + ": " + letter + " " + fixed4(value) + " is not a finite number"
            : std::string(what) + ": " + letter + " " + fixed4(value) + " is " +
                  (above ? "above" : "below") + " [AXIS_" + letter + "] " +
                  (above ? "MAX_LIMIT " : "MIN_LIMIT ") +
                  fixed4(above ? limits.max_limit : limits.min_limit) + " (machine coordinates)";
    report_.problems.push_back({file_, line, std::move(message)});
  }

  // One report per axis, side and line: an arc or a cycle may cross the same limit often.
  // Counts the violation; false when it is not reported (again, or past max_problems).
  bool first_report(int line, std::size_t axis, bool above) {
    const Reported key{line, axis, above};
    if (std::find(reported_.begin(), reported_.end(), key) != reported_.end()) return false;
    if (reported_.size() > 64) reported_.erase(reported_.begin());
    reported_.push_back(key);
    ++report_.limit_violations;
    return report_.problems.size() < options_.max_problems;
  }

  // An arc reaches beyond its end points where it turns back along one of its plane's axes:
  // the planner's segment names those points (motion::for_each_arc_extreme), and the path
  // between them is the one the servo loop samples. An arc the planner cannot make (ends not on
  // one circle, a start at the centre) is reported at its line, as the run would refuse it.
  void arc(const motion::Move& move) {
    ensure_start();
    ++report_.arcs;
    holes_.other_motion();
    std::string error;
    const auto segment = planner_.plan(move, position_, false, error);
    if (!segment) {
      // Keyed by no axis: one report per line.
      if (first_report(move.line, kAxes, false))
        report_.problems.push_back({file_, move.line, "arc: " + error});
    } else {
      const double mean_radius = segment->radius + segment->radius_change / 2;
      const auto normal = static_cast<std::size_t>(segment->normal_axis);
      report_.feed_length +=
          std::hypot(mean_radius * segment->sweep, move.end[normal] - position_[normal]);
      // The farthest the arc reaches each way along each axis of its plane is what is judged.
      Pose low = move.end, high = move.end;
      for_each_arc_extreme(*segment, [&](double s, int axis) {
        const auto a = static_cast<std::size_t>(axis);
        const double value = segment->point_at(s)[a];
        low[a] = std::min(low[a], value);
        high[a] = std::max(high[a], value);
      });
      for (const int axis : {segment->first_axis, segment->second_axis}) {
        const auto a = static_cast<std::size_t>(axis);
        if (low[a] < move.end[a]) reach_axis(a, low[a], move.line);
        if (high[a] > move.end[a]) reach_axis(a, high[a], move.line);
      }
      if (options_.preview != nullptr) preview_arc(*segment, move);
    }
    reach(move.end, move.line, "arc");
    check_joints(move, "arc");
    position_ = move.end;
  }

  // The arc as chords that stay within a tenth of the preview's tolerance of it (an arc of
  // very many turns gets at most kMaxChords).
  void preview_arc(const motion::Segment& segment, const motion::Move& move) {
    constexpr double kMaxChords = 20'000;
    const double radius = std::max(segment.radius, segment.radius + segment.radius_change);
    const double chord_error = std::max(options_.preview->tolerance() / 10, 1e-9);
    const double step = radius > chord_error ? 2 * std::acos(1 - chord_error / radius) : 1.0;
    const double chords = std::clamp(std::ceil(std::abs(segment.sweep) / step), 1.0, kMaxChords);
    Pose from = position_;
    for (double k = 1; k <= chords; ++k) {
      Pose to = move.end;
      if (k < chords) {
        const motion::AxisPose at = segment.point_at(segment.length * k / chords);
        std::copy(at.begin(), at.begin() + kAxes, to.begin());
      }
      options_.preview->move(PieceKind::arc, from, to, move.line);
      from = to;
    }
  }

  void reach_axis(std::size_t axis, double value, int line) {
    left_start_[axis] = true;
    extend(axis, value);
    check(axis, value, line, "arc");
  }

  struct Reported {
    int line;
    std::size_t axis;
    bool above;
    bool operator==(const Reported&) const = default;
  };

  const CheckOptions& options_;
  CheckReport& report_;
  std::string file_;
  config::MachineConfig machine_;
  motion::Planner planner_;
  const ProgramFeeder* feeder_ = nullptr;
  Pose position_{};
  Pose start_{};
  bool started_ = false;
  std::array<bool, kAxes> left_start_{};
  std::vector<Reported> reported_;
  HoleFinder holes_;
};

}  // namespace

std::string CheckProblem::to_string() const {
  return file + ":" + std::to_string(line) + ": " + message;
}

CheckReport check_program(const std::filesystem::path& program, const CheckOptions& options) {
  CheckReport report;
  report.limits_checked = options.machine != nullptr;
  report.inch_machine = options.interp.machine_units == interp::Units::inches;
  interp::Interpreter interp(options.interp);
  CheckSink sink(options, report, program.string());
  ProgramRunner runner(interp, options.interp.machine_units, {}, &sink.machine());
  runner.read_through_waits(true);
  runner.tap(&sink);
  sink.follow(runner.feeder());
  if (auto error = interp.open(program)) {
    report.error = std::move(error);
    return report;
  }
  report.dialect = interp.dialect();
  if (options.start_machine) {
    interp.set_machine_position(*options.start_machine);
    sink.start_at(*options.start_machine);
    motion::AxisPose at{};
    std::copy(options.start_machine->begin(), options.start_machine->end(), at.begin());
    runner.start(&at, false, interp.state().tool_in_spindle);
  }
  std::vector<motion::Move> reaching;
  if (options.from_line > 1) {
    const interp::InterpState state = interp.state();
    motion::AxisPose at{};
    for (std::size_t i = 0; i < kAxes; ++i) {
      at[i] = options.start_machine
                  ? (*options.start_machine)[i]
                  : state.g5x_offset[i] + state.g92_offset[i] + state.tool_offset[i];
    }
    // Without a machine there is no Z limit to rise to: Z stays at its height.
    const double safe_z = options.machine ? run_from_line_safe_z(*options.machine) : at[2];
    runner.skip_to(options.from_line, at, state.tool_in_spindle, safe_z);
    report.from_line = FromLineReport{options.from_line, false, state, {}};
  }
  const auto seconds = [&options] {
    if (!options.max_seconds_cpu) {
      return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
          .count();
    }
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
  };
  const double start = seconds();
  for (;;) {
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
      report.cancelled = true;
      report.stopped = CheckProblem{program.string(), interp.current_line(), "check cancelled"};
      break;
    }
    // Often enough that a few costly blocks (cycles of thousands of holes) still stop in time.
    if (options.max_seconds > 0 && report.blocks % 16 == 15 &&
        seconds() - start > options.max_seconds) {
      report.stopped = CheckProblem{program.string(), interp.current_line(),
                                    "check stopped after " + fixed4(options.max_seconds) + " s (" +
                                        std::to_string(report.blocks) +
                                        " blocks): the program runs too long to check"};
      break;
    }
    ProgramRunner::Budget one_block;
    one_block.max_blocks = 1;
    const bool skipping = runner.skipping();
    reaching.clear();
    sink.record = skipping ? &reaching : nullptr;
    const auto outcome = runner.advance(sink, one_block);
    sink.record = nullptr;
    // Refused at the line itself (cutter compensation, a line not run there): the line is
    // reached, the error says why it is not run from.
    if (skipping && outcome == ProgramRunner::Outcome::error &&
        runner.error().kind != ProgramRunner::Error::Kind::interpreter &&
        runner.error().kind != ProgramRunner::Error::Kind::ends_before_line) {
      report.from_line->state = interp.state();
      report.from_line->reached = true;
    }
    if (skipping && outcome != ProgramRunner::Outcome::error) {
      if (runner.skipping()) {
        report.from_line->state = interp.state();
      } else {
        report.from_line->reached = true;
        const auto lead_in = std::min(runner.lead_in(), reaching.size());
        report.from_line->lead_in.assign(reaching.begin(),
                                         reaching.begin() + static_cast<std::ptrdiff_t>(lead_in));
      }
    }
    if (outcome == ProgramRunner::Outcome::error) {
      // What the failing block queued before its error is checked too.
      runner.drain(sink);
      const ProgramRunner::Error& error = runner.error();
      if (error.kind == ProgramRunner::Error::Kind::interpreter) {
        report.error = error.interp;
        break;
      }
      if (!sink.stops_it)
        sink.stops_it = interp::InterpError{program.string(), error.line, 0, error.message};
    }
    runner.clear_stop();  // M0/M1/M60 take no time here
    ++report.blocks;
    if (options.preview != nullptr && options.preview->has_block()) {
      const interp::InterpState state = interp.state();
      const int mode = state.gcodes[1];
      const bool cycle = mode == 730 || mode == 740 || mode == 760 || (mode >= 810 && mode <= 890);
      PreviewFrame frame;
      for (std::size_t a = 0; a < 3; ++a) {
        frame.origin[a] = state.g5x_offset[a] + state.tool_offset[a];
        frame.g92[a] = state.g92_offset[a];
      }
      frame.rotation_deg = state.rotation_deg;
      options.preview->end_block(cycle, frame);
    }
    if (sink.stops_it) {
      report.error = sink.stops_it;
      break;
    }
    if (outcome == ProgramRunner::Outcome::ended) break;
  }
  report.holes = sink.holes();
  return report;
}

bool names_its_dialect(const std::filesystem::path& program) {
  // Read with either dialect as the default, a program that names its own is read in it both
  // times; one that does not follows the default.
  interp::InterpOptions options;
  options.dialect = interp::Dialect::linuxcnc;
  interp::Interpreter as_linuxcnc(options);
  options.dialect = interp::Dialect::numeryx;
  interp::Interpreter as_numeryx(options);
  return !as_linuxcnc.open(program) && !as_numeryx.open(program) &&
         as_linuxcnc.dialect() == as_numeryx.dialect();
}

}  // namespace cncd::pipeline
