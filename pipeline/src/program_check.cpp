#include "cncd/pipeline/program_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numbers>
#include <string_view>

#include "cncd/interp/to_machine.hpp"
#include "cncd/motion/soft_limits.hpp"
#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {

using interp::CanonCommand;
using interp::CanonKind;
using interp::kAxes;
using interp::Pose;

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

std::string number(double value) {
  char text[64];
  // %.4f of an absurd number would print hundreds of digits.
  std::snprintf(text, sizeof text, std::abs(value) <= 1e9 ? "%.4f" : "%.10g", value);
  return text;
}

// The unit vectors of the arc plane's first and second axes (program frame) in machine frame:
// the tracker's transform is a rotation about Z, a uniform scale and offsets, so their images
// stay orthogonal with the same orientation.
struct ArcFrame {
  Pose center{};
  Pose u{};
  Pose v{};
};

double dot(const Pose& a, const Pose& b) {
  double sum = 0;
  for (std::size_t i = 0; i < kAxes; ++i)
    sum += a[i] * b[i];
  return sum;
}

Pose minus(const Pose& a, const Pose& b) {
  Pose r{};
  for (std::size_t i = 0; i < kAxes; ++i)
    r[i] = a[i] - b[i];
  return r;
}

double xyz_distance(const Pose& a, const Pose& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

class CheckSink final : public interp::CanonSink {
 public:
  CheckSink(const CheckOptions& options, CheckReport& report, std::string file)
      : options_(options),
        report_(report),
        file_(std::move(file)),
        tracker_(options.interp.machine_units) {}

  void start_at(const Pose& machine) { position_ = machine; }

  void emit(const CanonCommand& command) override {
    if (options_.trace) options_.trace->emit(command);
    if (command.kind == CanonKind::arc_feed) {
      arc(command);
      return;
    }
    const CanonCommand out = tracker_.to_machine(command);
    switch (out.kind) {
      case CanonKind::straight_traverse:
      case CanonKind::straight_feed: {
        ensure_start();
        const bool feed = out.kind == CanonKind::straight_feed;
        ++(feed ? report_.feeds : report_.traverses);
        if (feed) report_.feed_length += xyz_distance(position_, out.pos);
        reach(out.pos, out.line, feed ? "feed move" : "rapid move");
        position_ = out.pos;
        break;
      }
      case CanonKind::dwell:
        ++report_.dwells;
        break;
      case CanonKind::change_tool:
      case CanonKind::change_tool_number:
        if (out.ivalue > 0) report_.tools.insert(out.ivalue);
        break;
      default:
        break;
    }
  }

 private:
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
    if (!options_.start_machine) position_ = tracker_.machine_pose(Pose{});
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

  void check(std::size_t axis, double value, int line, const char* what) {
    const config::MachineConfig* machine = options_.machine;
    if (!machine) return;
    const char letter = config::kAxisLetters[axis];
    if (machine->coordinates.find(letter) == std::string::npos) return;
    const config::AxisConfig& limits = machine->axes[axis];
    const bool finite = std::isfinite(value);
    const bool below = value < limits.min_limit - motion::kSoftLimitSlack;
    const bool above = value > limits.max_limit + motion::kSoftLimitSlack;
    if (finite && !below && !above) return;
    // One report per axis, side and line: an arc or a cycle may cross the same limit often.
    const Reported key{line, axis, above};
    if (std::find(reported_.begin(), reported_.end(), key) != reported_.end()) return;
    if (reported_.size() > 64) reported_.erase(reported_.begin());
    reported_.push_back(key);
    ++report_.limit_violations;
    if (report_.problems.size() >= options_.max_problems) return;
    std::string message =
        !finite
            ? std::string(what) + ": " + letter + " " + number(value) + " is not a finite number"
            : std::string(what) + ": " + letter + " " + number(value) + " is " +
                  (above ? "above" : "below") + " [AXIS_" + letter + "] " +
                  (above ? "MAX_LIMIT " : "MIN_LIMIT ") +
                  number(above ? limits.max_limit : limits.min_limit) + " (machine coordinates)";
    report_.problems.push_back({file_, line, std::move(message)});
  }

  // An arc reaches beyond its end points where it crosses the direction of an axis: for each
  // machine axis k the extremes of center + r (cos t u + sin t v) lie at t = atan2(v_k, u_k)
  // and opposite. The radius may change along the sweep (LinuxCNC allows a small difference
  // between start and end radius): it is interpolated, as are the helix axis and A..W.
  void arc(const CanonCommand& command) {
    const auto [first, second, normal] = plane_axes(command.plane);
    Pose end = command.pos;
    end[first] = command.first_end;
    end[second] = command.second_end;
    end[normal] = command.axis_end_point;
    Pose center = end;
    center[first] = command.first_axis;
    center[second] = command.second_axis;
    ensure_start();
    const CanonCommand out = tracker_.to_machine(command);
    ++report_.arcs;
    ArcFrame frame;
    frame.center = tracker_.machine_pose(center);
    const double scale = tracker_.length_factor();
    Pose step = center;
    step[first] += 1;
    frame.u = minus(tracker_.machine_pose(step), frame.center);
    step = center;
    step[second] += 1;
    frame.v = minus(tracker_.machine_pose(step), frame.center);
    for (std::size_t i = 0; i < kAxes; ++i) {
      frame.u[i] /= scale;
      frame.v[i] /= scale;
    }
    const Pose machine_end = out.pos;
    const Pose from_start = minus(position_, frame.center);
    const Pose from_end = minus(machine_end, frame.center);
    const double start_angle = std::atan2(dot(from_start, frame.v), dot(from_start, frame.u));
    const double end_angle = std::atan2(dot(from_end, frame.v), dot(from_end, frame.u));
    const double start_radius = std::hypot(dot(from_start, frame.u), dot(from_start, frame.v));
    const double end_radius = std::hypot(dot(from_end, frame.u), dot(from_end, frame.v));
    // Signed sweep: counterclockwise for positive rotation, |rotation| - 1 extra full turns.
    double sweep = end_angle - start_angle;
    const int turns = std::abs(command.rotation);
    if (command.rotation >= 0) {
      if (sweep <= 1e-12) sweep += kTwoPi;
      sweep += kTwoPi * std::max(0, turns - 1);
    } else {
      if (sweep >= -1e-12) sweep -= kTwoPi;
      sweep -= kTwoPi * std::max(0, turns - 1);
    }
    // Off-plane part of the start and end (helix axis, rotary and UVW axes), interpolated.
    auto off_plane = [&](const Pose& p, const Pose& rel) {
      Pose r = p;
      const double a = dot(rel, frame.u), b = dot(rel, frame.v);
      for (std::size_t i = 0; i < kAxes; ++i)
        r[i] -= frame.center[i] + a * frame.u[i] + b * frame.v[i];
      return r;
    };
    const Pose start_off = off_plane(position_, from_start);
    const Pose end_off = off_plane(machine_end, from_end);
    auto point_at = [&](double t) {  // t: angle offset from the start along the sweep
      const double f = sweep == 0 ? 1 : t / sweep;
      const double radius = start_radius + f * (end_radius - start_radius);
      const double angle = start_angle + t;
      Pose p{};
      for (std::size_t i = 0; i < kAxes; ++i) {
        p[i] = frame.center[i] +
               radius * (std::cos(angle) * frame.u[i] + std::sin(angle) * frame.v[i]) +
               start_off[i] + f * (end_off[i] - start_off[i]);
      }
      return p;
    };
    const double mean_radius = (start_radius + end_radius) / 2;
    report_.feed_length += std::hypot(mean_radius * sweep, end_off[normal] - start_off[normal]);
    for (std::size_t axis = 0; axis < kAxes; ++axis) {
      if (frame.u[axis] == 0 && frame.v[axis] == 0) continue;
      const double base = std::atan2(frame.v[axis], frame.u[axis]);
      for (double extreme : {base, base + std::numbers::pi}) {
        // The crossings of this direction inside the sweep, one a turn. The radius changes
        // linearly along the sweep, so the first and the last crossing are the farthest.
        double t = std::fmod(extreme - start_angle, kTwoPi);
        if (sweep > 0 && t < 0) t += kTwoPi;
        if (sweep < 0 && t > 0) t -= kTwoPi;
        if (std::abs(t) >= std::abs(sweep)) continue;
        const double last =
            t + std::copysign(kTwoPi, sweep) * std::floor((std::abs(sweep) - std::abs(t)) / kTwoPi);
        reach_axis(axis, point_at(t)[axis], command.line);
        reach_axis(axis, point_at(last)[axis], command.line);
      }
    }
    reach(machine_end, command.line, "arc");
    position_ = machine_end;
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
  interp::MachineTracker tracker_;
  Pose position_{};
  Pose start_{};
  bool started_ = false;
  std::array<bool, kAxes> left_start_{};
  std::vector<Reported> reported_;
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
  if (auto error = interp.open(program)) {
    report.error = std::move(error);
    return report;
  }
  if (options.start_machine) {
    interp.set_machine_position(*options.start_machine);
    sink.start_at(*options.start_machine);
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
    if (options.max_seconds > 0 && report.blocks % 4096 == 4095 &&
        seconds() - start > options.max_seconds) {
      report.stopped = CheckProblem{program.string(), interp.current_line(),
                                    "check stopped after " + number(options.max_seconds) + " s (" +
                                        std::to_string(report.blocks) +
                                        " blocks): the program runs too long to check"};
      break;
    }
    const auto step = interp.step(sink);
    if (step == interp::Interpreter::Step::error) {
      report.error = interp.error();
      break;
    }
    ++report.blocks;
    if (step == interp::Interpreter::Step::end) break;
  }
  return report;
}

std::string describe(const CheckReport& report) {
  const char* unit = report.inch_machine ? "in" : "mm";
  std::string text =
      "moves: " + std::to_string(report.traverses + report.feeds + report.arcs) + " (" +
      std::to_string(report.traverses) + " rapid, " + std::to_string(report.feeds) + " feed, " +
      std::to_string(report.arcs) + " arc), " + std::to_string(report.dwells) + " dwell" +
      (report.dwells == 1 ? "" : "s") + ", " + std::to_string(report.blocks) + " blocks\n";
  text += std::string("extents (machine coordinates, ") + unit + "):\n";
  bool any = false;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (!report.moved[axis]) continue;
    any = true;
    const bool angular = axis >= 3 && axis <= 5;
    text += std::string("  ") + config::kAxisLetters[axis] + " " + number(report.min[axis]) +
            " .. " + number(report.max[axis]) + (angular ? " deg" : "") + "\n";
  }
  if (!any) text += "  (no axis moves)\n";
  text += "tools:";
  if (report.tools.empty()) text += " none";
  for (const int tool : report.tools)
    text += " T" + std::to_string(tool);
  text += "\nfeed path: " + number(report.feed_length) + " " + unit + "\n";
  if (!report.limits_checked) {
    text += "soft limits: not checked (no --ini; interpreter defaults)\n";
  } else if (report.limit_violations == 0) {
    text += "soft limits: every move within them\n";
  } else {
    text += "soft limits: " + std::to_string(report.limit_violations) + " violation" +
            (report.limit_violations == 1 ? "" : "s") + "\n";
  }
  return text;
}

}  // namespace cncd::pipeline
