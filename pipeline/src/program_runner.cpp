#include "cncd/pipeline/program_runner.hpp"

#include <utility>

namespace cncd::pipeline {

using Clock = std::chrono::steady_clock;
using Push = motion::MoveQueue::Push;

ProgramRunner::ProgramRunner(interp::Interpreter& interp, interp::Units machine_units,
                             ProgramFeeder::MessageHandler on_message,
                             const config::MachineConfig* machine)
    : interp_(interp), feeder_(machine_units, std::move(on_message), machine) {
  // M428/M429: the interpreter goes on from where the feeder puts the tool in the new frame.
  interp_.set_tcp_switch(
      [this](const interp::Pose& at, bool on) { return feeder_.tcp_switched(at, on); });
}

void ProgramRunner::start(const motion::AxisPose* at, bool mdi, int tool) {
  feeder_.start_program(at, mdi);
  feeder_.set_tool(tool);
  error_ = {};
  failed_ = ended_ = stop_ = probe_wait_ = input_wait_ = stepping_ = false;
  step_budget_ = 0;
  skip_to_ = 0;
  lead_in_ = 0;
  skip_moved_ = false;
  skip_feed_.reset();
  sink_.shuttled = false;
  sink_.end_code = 0;
}

void ProgramRunner::skip_to(int line, const motion::AxisPose& at, int tool_in_spindle,
                            double safe_z) {
  safe_z_ = safe_z;
  skip_to_ = line > 1 ? line : 0;
  lead_in_ = 0;
  skip_moved_ = false;
  skip_feed_.reset();
  skip_from_ = at;
  skip_end_ = at;
  tool_at_start_ = tool_in_spindle;
}

void ProgramRunner::single_step(bool on, int blocks) {
  stepping_ = on;
  step_budget_ = on ? blocks : 0;
}

void ProgramRunner::probe_done(const motion::AxisPose& at) {
  feeder_.set_position(at);
  probe_wait_ = false;
}

ProgramRunner::Outcome ProgramRunner::fail(Error error) {
  error_ = std::move(error);
  failed_ = true;
  return Outcome::error;
}

ProgramRunner::Outcome ProgramRunner::advance(motion::MoveQueue& queue, const Budget& budget) {
  if (failed_) return Outcome::error;
  for (int blocks = 0;; ++blocks) {
    const Drained drained = feeder_.drain(queue);
    if (drained.result == Push::full) return Outcome::needs_room;
    if (drained.result == Push::refused)
      return fail({Error::Kind::refused, drained.line, queue.refusal(), {}});
    // The move held back for look-ahead goes out when no more come for now, so that the path
    // ends at rest where the program ends, stops, waits or a step is done.
    const Outcome rest = ended_        ? Outcome::ended
                         : stop_       ? Outcome::stop
                         : probe_wait_ ? Outcome::waiting_probe
                         : input_wait_ ? Outcome::waiting_input
                         : step_over() ? Outcome::step_done
                                       : Outcome::yielded;
    if (rest != Outcome::yielded) {
      queue.end_path();
      return rest;
    }
    if (budget.max_blocks > 0 && blocks >= budget.max_blocks) return Outcome::yielded;
    if (budget.until && (blocks & 63) == 63 && Clock::now() > *budget.until)
      return Outcome::yielded;
    // Nothing is read ahead of what the queue can take.
    if (!queue.ready()) return Outcome::needs_room;
    const int line_before = interp_.program_line();
    const auto step = interp_.step(sink_);
    if (step == interp::Interpreter::Step::error) {
      const auto& error = interp_.error();
      return fail({Error::Kind::interpreter, error ? error->line : interp_.current_line(),
                   error ? error->message : "interpreter error", error});
    }
    if (stepping_) --step_budget_;
    if (auto outcome = after_block(step == interp::Interpreter::Step::end, line_before))
      return *outcome;
  }
}

std::optional<ProgramRunner::Outcome> ProgramRunner::after_block(bool program_ended,
                                                                 int line_before) {
  if (skip_to_ > 0) {
    if (auto outcome = skip_block(program_ended, line_before)) return outcome;
  }
  // A skipped line's wait is dropped with it; its M0/M1 does not stop a run from line.
  if (feeder_.take_input_wait()) input_wait_ = skip_to_ == 0 && !through_waits_;
  if (feeder_.take_probe()) probe_wait_ = skip_to_ == 0 && !through_waits_;
  if (feeder_.take_stop()) stop_ = skip_to_ == 0;
  if (const auto& unsupported = feeder_.unsupported())
    return fail({Error::Kind::unsupported, unsupported->line, unsupported->why, {}});
  if (program_ended) ended_ = true;
  return std::nullopt;
}

std::optional<ProgramRunner::Outcome> ProgramRunner::skip_block(bool program_ended,
                                                                int line_before) {
  // Lines of the program's own file: a subroutine file it calls has its own numbers.
  const int line = interp_.program_line();
  if (line < skip_to_) {
    if (program_ended) {
      return fail({Error::Kind::ends_before_line,
                   line,
                   "the program ends at line " + std::to_string(line) + ", before line " +
                       std::to_string(skip_to_),
                   {}});
    }
    if (feeder_.drop_pending(skip_end_)) skip_moved_ = true;
    feeder_.clear_holds();  // the tool changes and user M codes of the lines skipped
    return std::nullopt;
  }
  if (line_before < skip_to_ && line > skip_to_) {
    // The block read past the line without running it: the line is in a subroutine's
    // definition or a branch or loop not taken there. Starting later would not be that line.
    return fail({Error::Kind::not_run,
                 skip_to_,
                 "line " + std::to_string(skip_to_) +
                     " is not run where the program first reaches it (it is inside a "
                     "subroutine definition, or a branch or loop skipped there): run from the "
                     "line that calls it or from one the program runs",
                 {}});
  }
  // Under G41/G42 the interpreter holds each move back until it has read the next: the move
  // the line starts from (the one before it, ending at the compensated corner) comes out with
  // a later block. The lines before keep being skipped until a move of the line or a later one
  // is out; the way then leads to where the compensated path left off. A stop or wait of the
  // line or a later one (M0, M1, M60, M66) has put out every move before it: the way leads
  // there, and the machine stops or waits as the program says.
  if (!skip_feed_) skip_feed_ = feeder_.feed_in_force();
  if (interp_.state().gcodes[4] > 400 && !program_ended && !feeder_.moves_from(skip_to_) &&
      !feeder_.waits_seen()) {
    if (feeder_.drop_pending_before(skip_to_, skip_end_)) skip_moved_ = true;
    return std::nullopt;
  }
  if (feeder_.drop_pending_before(skip_to_, skip_end_)) skip_moved_ = true;
  const std::size_t own = feeder_.pending_count();
  if (skip_moved_) {
    if (auto why = feeder_.approach_first(skip_from_, skip_end_, safe_z_, line, skip_feed_))
      return fail({Error::Kind::approach, line, std::move(*why), {}});
  }
  // The spindle and coolant as the skipped lines left them, before the machine moves there.
  feeder_.restore_io_state();
  // A skipped M6 (or M61) left another tool in force than the one in the spindle: its length
  // is already in the line's positions, so the operator puts it in before anything moves.
  if (const int in_force = interp_.state().tool_in_spindle; in_force != tool_at_start_)
    feeder_.change_tool_first(in_force, line, skip_from_, tool_at_start_);
  lead_in_ = feeder_.pending_count() - own;
  skip_to_ = 0;
  return std::nullopt;
}

}  // namespace cncd::pipeline
