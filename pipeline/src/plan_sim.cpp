#include "cncd/pipeline/plan_sim.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>

#include "cncd/motion/planner.hpp"
#include "cncd/motion/servo_loop.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_geometry.hpp"
#include "cncd/pipeline/program_runner.hpp"
#include "plan_drive.hpp"

namespace cncd::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// One simulation run: the interpreter feeding the planner and the servo loop as the daemon's
// the daemon's task does (through ProgramRunner), the loop stepped in virtual time. Operator
// messages are not passed on: the simulation must not log them as if the program ran.
class Simulation final : motion::MoveQueue {
 public:
  Simulation(const config::MachineConfig& machine, std::string program,
             const PlanSimOptions& options, PlanSimResult& result)
      : machine_(machine),
        program_(std::move(program)),
        options_(options),
        result_(result),
        interp_(options.interp),
        runner_(interp_, machine_units(machine), {}, &machine),
        planner_(machine) {
    runner_.read_through_waits(true);
  }

  void run() {
    if (auto error = interp_.open(program_)) {
      result_.error = CheckProblem{error->file, error->line, error->message};
      return;
    }
    if (!start_machine()) return;
    const int tool = interp_.state().tool_in_spindle;
    runner_.start(&previous_, false, tool);
    if (options_.from_line > 1)
      runner_.skip_to(options_.from_line, previous_, tool, run_from_line_safe_z(machine_));
    std::uint64_t& cycle = cycle_;
    for (;;) {
      if (!feed()) return;
      const motion::Status before = loop_->status();
      const std::uint64_t done_before = before.segments_done - base_;
      const std::uint64_t moves_before = before.moves_done - moves_base_;
      if (runner_.ended() && runner_.drained() && !planner_.holding() &&
          planner_.output().empty() && done_before >= pushed_ &&
          before.motion == motion::MotionState::idle)
        break;
      if ((cycle & 1023) == 0 && over_budget(before.line)) break;
      const double begin_s = static_cast<double>(cycle) * result_.period_s;
      const double cpu_start = options_.measure ? thread_cpu_s() : 0.0;
      loop_->cycle(0);
      if (options_.measure) result_.servo_cpu_s += thread_cpu_s() - cpu_start;
      ++cycle;
      const motion::Status s = loop_->status();
      if (s.fault_reason[0] != '\0') {
        result_.error = CheckProblem{program_, s.line, s.fault_reason};
        break;
      }
      if (s.path_errors != path_errors_base_) {
        // The servo loop stopped the path (a spindle that did not reach its speed in time):
        // the machine would end the program there.
        result_.error = CheckProblem{program_, s.line, motion::format_event(s.path_error)};
        break;
      }
      const std::uint64_t done = s.segments_done - base_;
      // Move i starts when move i - 1 is complete: the daemon counts moves the same way.
      const std::uint64_t moves_done = s.moves_done - moves_base_;
      for (std::uint64_t i = moves_before + 1; i <= moves_done && i < result_.move_start_s.size();
           ++i)
        result_.move_start_s[i] = begin_s;
      const double t = static_cast<double>(cycle) * result_.period_s;
      if (options_.on_sample || options_.on_period) {
        // The spindle where it stands at the end of the period is what the next one reads.
        if (sample_pending_) hand_on_sample(s.spindle.revolutions);
        sample_pending_ = true;
        sample_ = {t, s.commanded, s.joint_commanded, s.tip_commanded, s.tcp, 0.0};
        sample_revolutions_ = s.spindle.revolutions;
      }
      if (options_.measure) measure(s, done);
    }
    // The last period's spindle reading stands for its end: the program ends at rest.
    if (sample_pending_) hand_on_sample(sample_revolutions_);
    result_.cycles = cycle;
    result_.cycle_time_s = static_cast<double>(cycle) * result_.period_s;
  }

 private:
  void hand_on_sample(double revolutions) {
    sample_.spindle = revolutions;
    if (options_.on_sample) options_.on_sample(sample_.t, sample_.axes, revolutions);
    if (options_.on_period) options_.on_period(sample_);
  }

  // Machine on at the start position, all joints as if homed there: the planner checks the
  // soft limits as it does for a homed machine.
  bool start_machine() {
    interp::Pose start{};
    if (options_.start_machine) {
      start = *options_.start_machine;
    } else {
      const interp::InterpState state = interp_.state();
      for (std::size_t i = 0; i < start.size(); ++i)
        start[i] = state.g5x_offset[i] + state.g92_offset[i] + state.tool_offset[i];
    }
    interp_.set_machine_position(start);
    std::vector<int> joints;
    for (std::size_t j = 0; j < machine_.joints.size() && j < motion::kJoints; ++j)
      joints.push_back(static_cast<int>(j));
    motion::AxisPose start_axes{};
    std::copy_n(start.begin(), start_axes.size(), start_axes.begin());
    motion::JointArray joint_start{};
    motion::make_kinematics(machine_)->inverse(start_axes, motion::kAllAxes, joint_start);
    if (auto problem = drive_.configure(machine_, joints); !problem.empty()) {
      result_.error = CheckProblem{program_, 0, "simulated drives: " + problem};
      return false;
    }
    loop_ = std::make_unique<motion::ServoLoop>(
        machine_, std::vector<motion::DriverBinding>{{&drive_, joints}});
    loop_->set_start_positions(joint_start);
    loop_->commands().push(motion::Command{motion::Command::Kind::reset_estop});
    loop_->commands().push(motion::Command{motion::Command::Kind::on});
    loop_->cycle(0);
    loop_->cycle(0);
    const motion::Status status = loop_->status();
    if (status.machine != motion::MachineState::on) {
      result_.error = CheckProblem{
          program_, 0,
          std::string("the simulated machine does not turn on: ") + status.fault_reason};
      return false;
    }
    base_ = status.segments_done;
    moves_base_ = status.moves_done;
    path_errors_base_ = status.path_errors;
    programmed_end_ = status.commanded;
    planner_.reset(status.commanded);
    previous_ = status.commanded;
    previous_joints_ = status.joint_commanded;
    result_.joint_count = status.joint_count;
    return true;
  }

  // Fills the segment queue as far as it goes, reading the program as needed. False on error.
  // The planner holds the newest move back for look-ahead and is flushed at stop points,
  // program stops and the program's end, as in the daemon.
  bool feed() {
    using Outcome = ProgramRunner::Outcome;
    ProgramRunner::Budget budget;
    budget.max_blocks = 4096;
    for (;;) {
      switch (runner_.advance(*this, budget)) {
        case Outcome::needs_room:
          return true;
        case Outcome::ended:
          pump();
          return true;
        case Outcome::stop:
          // M0/M1/M60 wait for the operator: the estimate leaves that time out, but the machine
          // comes to rest there.
          runner_.clear_stop();
          break;
        case Outcome::error:
          fail(runner_.error());
          return false;
        default:
          // A program reading thousands of blocks without a move still answers the budget.
          if (over_budget(interp_.current_line())) return false;
          break;
      }
    }
  }

  void fail(const ProgramRunner::Error& error) {
    using Kind = ProgramRunner::Error::Kind;
    if (error.kind == Kind::refused) return;  // push_move() has said why
    result_.error = error.interp ? CheckProblem{error.interp->file, error.line, error.message}
                                 : CheckProblem{program_, error.line, error.message};
  }

  // MoveQueue: the next move goes to the planner once its output is in the servo loop's ring.
  bool ready() override { return pump(); }

  Push push_move(const motion::Move& programmed) override {
    // No operator changes tools and no input changes here: holds and input waits take no time.
    motion::Move move = programmed;
    using Action = motion::IoAction::Kind;
    if (move.kind == motion::Move::Kind::action &&
        (move.action.kind == Action::hold || move.action.kind == Action::wait_input))
      move.action.kind = Action::none;
    // Nothing is touched here: a probing move runs its whole length (the longest it can take),
    // and the program reads on from its end.
    move.probe = motion::ProbeMode::none;
    bound(move);
    std::string error;
    const double cpu_start = thread_cpu_s();
    const bool planned = planner_.push(move, true, error);
    result_.planner_cpu_s += thread_cpu_s() - cpu_start;
    if (!planned) {
      result_.error = CheckProblem{program_, move.line, error};
      return Push::refused;
    }
    // Every pushed move is counted once in Status::moves_done, whichever segment (a blend
    // arc, a merged line) completes it: its line is its own, not that segment's.
    if (move.kind != motion::Move::Kind::action) result_.move_line.push_back(move.line);
    return Push::accepted;
  }

  void end_path() override { planner_.flush(); }
  std::string refusal() const override { return result_.error ? result_.error->message : ""; }

  // Hands the planner's final segments to the servo loop; false when the ring is full.
  bool pump() {
    auto& out = planner_.output();
    while (!out.empty()) {
      if (!loop_->segments().push(out.front())) return false;
      account(out.front());
      out.pop_front();
    }
    return true;
  }

  void account(const motion::Segment& segment) {
    ++pushed_;
    if (options_.on_segment) options_.on_segment(segment);
    // A blend arc is part of the moves it joins; a segment may also complete several moves.
    for (std::uint32_t k = 0; k < segment.moves; ++k) {
      result_.move_start_s.push_back(result_.moves == 0 ? 0.0
                                                        : std::numeric_limits<double>::quiet_NaN());
      ++result_.moves;
    }
    if (options_.measure) window_.push_back(segment);
  }

  // Adds the programmed move (not the planner's segments, which blends shorten) to the bounds.
  void bound(const motion::Move& move) {
    if (move.kind == motion::Move::Kind::action) return;  // no time and no path
    std::string error;
    const auto segment = planner_.plan(move, programmed_end_, false, error);
    if (!segment) return;  // push() reports it
    // A tap goes down its line and back to where it started.
    const bool tap = segment->spindle_sync == motion::SpindleSync::tap;
    programmed_end_ = tap ? segment->start : segment->end;
    if (options_.on_move) options_.on_move(*segment);
    if (segment->kind == motion::Segment::Kind::dwell) {
      result_.feed_bound_s += segment->dwell_s;
      result_.exact_stop_bound_s += segment->dwell_s;
    } else {
      const MoveLimits limits = move_limits(machine_, *segment);
      const double ways = tap ? 2.0 : 1.0;
      if (segment->length > 0 && limits.velocity < 1e300)
        result_.feed_bound_s += ways * segment->length / limits.velocity;
      result_.exact_stop_bound_s +=
          ways * rest_to_rest_s(segment->length, limits.velocity, limits.acceleration);
    }
  }

  // Sets `stopped` and returns true when a budget is used up or the caller cancelled.
  bool over_budget(int line) {
    std::string why;
    const double machine_s = static_cast<double>(cycle_) * result_.period_s;
    if (options_.cancel && options_.cancel->load(std::memory_order_relaxed)) {
      why = "simulation cancelled";
    } else if (options_.max_machine_s > 0 && machine_s > options_.max_machine_s) {
      why = "the program runs longer than " + std::to_string(options_.max_machine_s) +
            " s of machine time";
    } else if (options_.max_moves > 0 && pushed_ > options_.max_moves) {
      why = "the program has more than " + std::to_string(options_.max_moves) + " moves";
    } else if (options_.max_wall_s > 0 &&
               std::chrono::duration<double>(Clock::now() - wall_start_).count() >
                   options_.max_wall_s) {
      why = "simulation stopped after " + std::to_string(options_.max_wall_s) + " s";
    }
    if (why.empty()) return false;
    result_.stopped = CheckProblem{program_, line, why};
    return true;
  }

  void measure(const motion::Status& s, std::uint64_t done) {
    const double period = result_.period_s;
    for (int i = 0; i < motion::kAxes; ++i) {
      if (!machine_.axes[static_cast<std::size_t>(i)].present) continue;
      const double v = (s.commanded[i] - previous_[i]) / period;
      const double a = (v - velocity_[i]) / period;
      result_.peak_velocity[i] = std::max(result_.peak_velocity[i], std::abs(v));
      result_.peak_acceleration[i] = std::max(result_.peak_acceleration[i], std::abs(a));
      velocity_[i] = v;
    }
    previous_ = s.commanded;
    for (std::size_t j = 0; j < static_cast<std::size_t>(result_.joint_count); ++j) {
      const double v = (s.joint_commanded[j] - previous_joints_[j]) / period;
      const double a = (v - joint_velocity_[j]) / period;
      result_.joint_peak_velocity[j] = std::max(result_.joint_peak_velocity[j], std::abs(v));
      result_.joint_peak_acceleration[j] =
          std::max(result_.joint_peak_acceleration[j], std::abs(a));
      joint_velocity_[j] = v;
    }
    previous_joints_ = s.joint_commanded;
    // The sample lies on the move under way or, where the path blends, on a neighbour.
    while (!window_.empty() && window_first_ + 3 <= done) {
      window_.pop_front();
      ++window_first_;
    }
    double nearest = std::numeric_limits<double>::infinity();
    const std::uint64_t last = std::min<std::uint64_t>(done + 2, window_first_ + window_.size());
    for (std::uint64_t i = window_first_; i < last; ++i)
      nearest = std::min(nearest, distance_to_path(window_[i - window_first_], s.commanded));
    if (std::isfinite(nearest) && nearest > result_.max_deviation) {
      result_.max_deviation = nearest;
      result_.max_deviation_line = s.line;
    }
  }

  const config::MachineConfig& machine_;
  std::string program_;
  const PlanSimOptions& options_;
  PlanSimResult& result_;
  interp::Interpreter interp_;
  ProgramRunner runner_;
  motion::Planner planner_;
  PlanDrive drive_;
  std::unique_ptr<motion::ServoLoop> loop_;
  const Clock::time_point wall_start_ = Clock::now();
  std::uint64_t cycle_ = 0;             // servo periods since the program started
  std::uint64_t base_ = 0;              // segments done before the program
  std::uint64_t moves_base_ = 0;        // moves done before the program
  std::uint64_t path_errors_base_ = 0;  // path errors before the program
  motion::AxisPose programmed_end_{};   // where the last programmed move ends
  std::uint64_t pushed_ = 0;            // segments queued by the program
  motion::AxisPose previous_{};
  motion::AxisPose velocity_{};
  motion::JointArray previous_joints_{};
  motion::JointArray joint_velocity_{};
  std::deque<motion::Segment> window_;  // queued segments from index window_first_ on
  // The sample of the last period, handed on with the spindle's next reading.
  bool sample_pending_ = false;
  PlanSample sample_;
  double sample_revolutions_ = 0;
  std::uint64_t window_first_ = 0;
};

}  // namespace

PlanSimResult simulate_plan(const config::MachineConfig& machine,
                            const std::filesystem::path& program, const PlanSimOptions& options) {
  const auto wall_start = Clock::now();
  PlanSimResult result;
  result.period_s = static_cast<double>(machine.servo_period_ns) * 1e-9;
  auto simulation = std::make_unique<Simulation>(machine, program.string(), options, result);
  simulation->run();
  result.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return result;
}

}  // namespace cncd::pipeline
