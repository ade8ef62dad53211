// ProgramRunner: the one loop that runs a program, from the interpreter through the feeder to a
// motion::MoveQueue. The daemon's task (runs, MDI, run from line, single steps), the plan
// simulation and the offline check all read programs through it, so they read them alike.
// advance() reads blocks and queues their moves until something stops it, and says what:
// the caller acts on that (waits for room, for the probe, for the operator) and calls again.
// One thread at a time.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "cncd/interp/canon.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/motion/move_queue.hpp"
#include "cncd/pipeline/feeder.hpp"

namespace cncd::pipeline {

class ProgramRunner {
 public:
  enum class Outcome {
    yielded,        // the budget of blocks or time is used up: call again
    needs_room,     // the queue has no room: call again when it has
    stop,           // M0/M1/M60 read: every move before it is queued, the path ends there
    step_done,      // single step: the block is read and its moves queued
    waiting_probe,  // a probing move is queued: call probe_done() once it is over
    waiting_input,  // M66 is queued: call input_done() once the machine has waited
    ended,          // the program's end is read and every move queued
    error,          // error() says where and why; nothing more is read
  };
  struct Error {
    enum class Kind {
      interpreter,       // the interpreter's error (interp set)
      refused,           // the queue refused a move (message is its refusal())
      unsupported,       // something this machine cannot run
      ends_before_line,  // run from line: the program ends before that line
      approach,          // run from line: no way to the line's start (no feed for Z down)
      not_run            // run from line: the program passes the line without running it
    };
    Kind kind = Kind::interpreter;
    int line = 0;
    std::string message;
    std::optional<interp::InterpError> interp;
  };
  struct Budget {
    int max_blocks = 0;  // 0: no limit
    std::optional<std::chrono::steady_clock::time_point> until;
  };

  // `interp` outlives the runner; the feeder's arguments are ProgramFeeder's.
  ProgramRunner(interp::Interpreter& interp, interp::Units machine_units,
                ProgramFeeder::MessageHandler on_message = {},
                const config::MachineConfig* machine = nullptr);
  // The interpreter asks the runner's feeder where M428/M429 put the tool: not copied, and
  // the interpreter forgets it when the runner goes.
  ~ProgramRunner() { interp_.set_tcp_switch({}); }
  ProgramRunner(const ProgramRunner&) = delete;
  ProgramRunner& operator=(const ProgramRunner&) = delete;

  // A new run of what the interpreter has open; `at` is where the machine stands (machine
  // coordinates) when known, `tool` the tool in the spindle.
  void start(const motion::AxisPose* at, bool mdi, int tool);
  // Run from line: the blocks before `line` are read for their state, their moves dropped. At
  // the line, in this order: the tool they leave in force is put in (the machine has
  // `tool_in_spindle`), the spindle and coolant they leave are started (the spindle at speed),
  // Z rises from `at` to `safe_z` (machine coordinates), the other axes go over where those
  // lines leave the tool and Z comes down to it at the feed in force.
  void skip_to(int line, const motion::AxisPose& at, int tool_in_spindle, double safe_z);
  // Whether the lines before the start are still being read, and whether they moved.
  bool skipping() const { return skip_to_ > 0; }
  bool skipped_motion() const { return skip_moved_; }
  // The moves of the way to the line's start (0 before it is reached or when there is none).
  int approach_moves() const { return feeder_.approach_moves(); }
  // The moves and actions put in front of the line's own (tool, spindle, coolant, the way).
  std::size_t lead_in() const { return lead_in_; }
  // Single steps: after `blocks` more blocks advance() says step_done; 0 with `on` false reads
  // on freely.
  void single_step(bool on, int blocks);
  bool step_over() const { return stepping_ && step_budget_ == 0; }

  // Reads and queues as far as it can within `budget`.
  Outcome advance(motion::MoveQueue& queue, const Budget& budget);
  // Hands the pending moves on without reading (the offline check counts what the block that
  // failed queued before its error).
  Drained drain(motion::MoveQueue& queue) { return feeder_.drain(queue); }
  // ProgramFeeder::program_start().
  motion::AxisPose program_start(const motion::AxisPose& joints, bool mdi) const {
    return feeder_.program_start(joints, mdi);
  }
  const Error& error() const { return error_; }

  // The machine has stopped at the M0/M1/M60: reading goes on.
  void clear_stop() { stop_ = false; }
  bool stopped() const { return stop_; }
  // The probing move is over (the caller has given the interpreter its result) and the machine
  // stands at `at`; the input wait is over.
  void probe_done(const motion::AxisPose& at);
  // Probing moves and M66 are not waited for (nothing is touched, no input changes: the plan
  // simulation and the offline check read on from the move's programmed end).
  void read_through_waits(bool on) { through_waits_ = on; }
  void input_done() { input_wait_ = false; }
  bool waiting_probe() const { return probe_wait_; }
  bool waiting_input() const { return input_wait_; }
  bool ended() const { return ended_; }
  // How the program ended: 30 (M30), 2 (M2), 0 (a closing '%', or not ended yet).
  int end_code() const { return sink_.end_code; }
  // Whether no move is left for the queue.
  bool drained() const { return !feeder_.has_pending(); }
  // Moves and actions (spindle, outputs, waits) the queue has taken since start().
  std::uint64_t moves_queued() const { return feeder_.moves_queued(); }
  std::uint64_t actions_queued() const { return feeder_.actions_queued(); }

  // Every canonical command goes to `tap` before the feeder (a printer, a counter); null: none.
  void tap(interp::CanonSink* tap) { sink_.tap = tap; }
  ProgramFeeder& feeder() { return feeder_; }
  const ProgramFeeder& feeder() const { return feeder_; }

 private:
  struct Sink final : interp::CanonSink {
    Sink(const interp::Interpreter& from, ProgramFeeder& to) : interp(from), feeder(to) {}
    void emit(const interp::CanonCommand& command) override {
      if (tap != nullptr) tap->emit(command);
      // M30 is a pallet shuttle and the end; M60's shuttle is followed by a stop instead.
      if (std::holds_alternative<interp::ProgramEnd>(command.op)) end_code = shuttled ? 30 : 2;
      shuttled = std::holds_alternative<interp::PalletShuttle>(command.op);
      // Inside a subroutine file the moves carry the line of the call in the program's own
      // file: the status, its progress and the errors count the program's lines.
      if (const int line = interp.program_line(); line != interp.current_line()) {
        interp::CanonCommand in_program = command;
        in_program.line = line;
        feeder.emit(in_program);
        return;
      }
      feeder.emit(command);
    }
    const interp::Interpreter& interp;
    ProgramFeeder& feeder;
    interp::CanonSink* tap = nullptr;
    bool shuttled = false;  // the last command was a pallet shuttle
    int end_code = 0;
  };

  Outcome fail(Error error);
  // After a block: run from line, the waits it queued, what the machine cannot run.
  std::optional<Outcome> after_block(bool program_ended, int line_before);
  // Run from line: drops the block's moves before the line; at the line, what goes in front.
  // `line_before` is the program line the block started after.
  std::optional<Outcome> skip_block(bool program_ended, int line_before);

  interp::Interpreter& interp_;
  ProgramFeeder feeder_;
  Sink sink_{interp_, feeder_};
  Error error_;
  bool failed_ = false;
  bool ended_ = false;
  bool stop_ = false;
  bool probe_wait_ = false;
  bool input_wait_ = false;
  bool through_waits_ = false;
  bool stepping_ = false;
  int step_budget_ = 0;
  int skip_to_ = 0;
  bool skip_moved_ = false;
  motion::AxisPose skip_end_{};
  // The feed in force when the line was read (cutter compensation reads on past it).
  std::optional<double> skip_feed_;
  motion::AxisPose skip_from_{};
  int tool_at_start_ = 0;
  double safe_z_ = 0;
  std::size_t lead_in_ = 0;
};

}  // namespace cncd::pipeline
