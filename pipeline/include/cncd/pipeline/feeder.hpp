// ProgramFeeder: the canonical-command sink that turns the interpreter's output into motion
// moves (machine coordinates and units) and remembers spindle, coolant and tool state, and
// what the program waits for. ProgramRunner reads a program through it and hands its moves to
// a motion::MoveQueue. One thread at a time.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/canon.hpp"
#include "cncd/interp/to_machine.hpp"
#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/move_queue.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::pipeline {

struct Drained {
  motion::MoveQueue::Push result = motion::MoveQueue::Push::accepted;  // accepted: none left
  int line = 0;                                                        // the refused move's line
};

// What a hold (IoAction::Kind::hold) waits for, by its id: the task shows it and answers it.
struct HoldInfo {
  motion::IoAction::Hold kind = motion::IoAction::Hold::none;
  int line = 0;
  int tool = 0;            // tool_change: the tool to put in
  int tool_before = 0;     // tool_change: the tool in force before it, until it is put in
  interp::UserMCode user;  // user_m: what to run
};

// Why `machine` cannot make the move from `start` to `end` (machine coordinates): it moves an
// axis that [TRAJ] COORDINATES does not give the machine; or nothing.
std::optional<std::string> axis_missing(const config::MachineConfig& machine,
                                        const motion::AxisPose& start, const motion::AxisPose& end);
// Why `machine` cannot move in step with its spindle (no position to follow), or nothing.
std::optional<std::string> spindle_position_missing(const config::MachineConfig& machine);
// Why `machine` cannot orient its spindle (M19): no position to steer it by; or nothing.
std::optional<std::string> spindle_cannot_orient(const config::MachineConfig& machine);
// Why `machine` cannot tap rigidly (its spindle cannot reverse), or nothing.
std::optional<std::string> spindle_cannot_reverse(const config::MachineConfig& machine);
// Why `machine`'s axes cannot follow a thread (G33) from `start` to `end` (machine
// coordinates) of `per_rev` machine units a revolution with the spindle at `rpm` (the speed
// it is commanded at 100 % spindle override; `programmed` is the S word, `direction` M3 1 or
// M4 -1), or nothing.
std::optional<std::string> thread_too_fast(const config::MachineConfig& machine,
                                           const motion::AxisPose& start,
                                           const motion::AxisPose& end, double per_rev, double rpm,
                                           int direction, double programmed);

class ProgramFeeder final : public interp::CanonSink {
 public:
  // How long an orientation (M19 without Q, G87) may take before the program stops.
  static constexpr double kOrientTimeoutS = 30.0;
  // Operator messages (MSG) in the program, with their line; none = dropped.
  using MessageHandler = std::function<void(int line, const std::string& text)>;

  // `machine` (which must outlive the feeder) gives the tool change position; null: none.
  explicit ProgramFeeder(interp::Units machine_units, MessageHandler on_message = {},
                         const config::MachineConfig* machine = nullptr)
      : tracker_(machine_units),
        on_message_(std::move(on_message)),
        machine_(machine),
        kins_(machine != nullptr ? motion::make_kinematics(*machine) : nullptr) {}
  void emit(const interp::CanonCommand& command) override;
  // Receives warnings about the program (an S the spindle's limits clamp), with their line.
  void on_warning(MessageHandler handler) { on_warning_ = std::move(handler); }
  // Resets what a new program run must not inherit; `at` is where the machine stands
  // (machine coordinates), when known.
  // An MDI block (`mdi`) keeps the feed mode the interpreter keeps for it; a program starts in
  // G94, as the interpreter does.
  void start_program(const motion::AxisPose* at = nullptr, bool mdi = false);
  // Puts the spindle and coolant as the program has left them in front of the pending moves
  // (run from line: the lines skipped set them).
  void restore_io_state();
  // Run from line: the tool the skipped lines left in force is not the one in the spindle.
  // Puts that tool change in front of the pending moves as an M6 makes it (the spindle
  // stopped unless TOOL_CHANGE_WITH_SPINDLE_ON, the traverse to TOOL_CHANGE_POSITION, the
  // hold for the operator); `at` is where the machine stands (machine coordinates), `in_spindle`
  // the tool it has.
  void change_tool_first(int number, int line, const motion::AxisPose& at, int in_spindle);
  // Run from line: the way from `from`, where the machine stands, to `to`, where the lines
  // skipped leave the tool, in front of the pending moves: Z up to `safe_z` (it stays where it
  // is when higher), the other axes over `to` at rapid, then Z down to `to` at the feed in
  // force (or `feed`, units per second, when given). An error (nothing queued) when the way
  // down has no feed.
  std::optional<std::string> approach_first(const motion::AxisPose& from,
                                            const motion::AxisPose& to, double safe_z, int line,
                                            std::optional<double> feed = std::nullopt);
  // The feed of the next feed move, machine units per second.
  double feed_in_force() const { return feed_per_second(); }
  // The moves approach_first() queued (0 to 3).
  int approach_moves() const { return approach_moves_; }
  // Whether `move` is a stop point (a zero dwell, G4 P0 included): nothing to execute, the
  // planner is flushed there.
  static bool stop_point(const motion::Move& move) {
    return move.kind == motion::Move::Kind::dwell && !(move.dwell_s > 0);
  }
  // Hands the pending moves to `queue` in order, ending its path at stop points, until none is
  // left, the queue has no room, or it refuses one (which stays pending).
  Drained drain(motion::MoveQueue& queue);
  // Where the machine stands after a move that ended early (a probing move that tripped): the
  // next move starts there (machine coordinates).
  void set_position(const motion::AxisPose& at) { end_ = at; }
  // Where `machine` (machine coordinates: the joints' axes, or under TCP the tool tip in the
  // part's frame) lies once TCP is switched `on`: itself when that changes nothing.
  motion::AxisPose tcp_switched(const motion::AxisPose& machine, bool on) const;
  // Where the program stands when the machine's axes stand at `joints`: under TCP kept from
  // the last MDI command, the tool tip in the part's frame.
  motion::AxisPose program_start(const motion::AxisPose& joints, bool mdi) const {
    return mdi && tcp_ ? in_frame(joints, true) : joints;
  }
  // Offsets, units and feed as the commands so far left them.
  const interp::MachineTracker& tracker() const { return tracker_; }

  bool has_pending() const { return !pending_.empty(); }
  // Tool centre point control as the commands so far left it (M428 on, M429 off): the moves
  // read next carry Move::tcp.
  bool tcp() const { return tcp_; }
  std::size_t pending_count() const { return pending_.size(); }
  // Moves and actions the queue has taken since start_program().
  std::uint64_t moves_queued() const { return moves_queued_; }
  std::uint64_t actions_queued() const { return actions_queued_; }
  // Drops the pending moves (run from line: the lines before it); true with `end` set where
  // the last of them that moves ends.
  bool drop_pending(motion::AxisPose& end);
  // The same for the pending moves at the front that come from lines before `line` (moves
  // cutter compensation held back until the line's block was read).
  bool drop_pending_before(int line, motion::AxisPose& end);
  // Whether a pending move (not a dwell or an action) comes from `line` or a later one.
  bool moves_from(int line) const;

  // What the stream has reached since the flag was last taken: M0/M1/M60 (a stop), M66 (the
  // interpreter must not read on until the machine has waited and its result is in #5399) and
  // a probing move (likewise, until Interpreter::set_probe_result() has the answer).
  bool take_stop() { return std::exchange(stop_seen_, false); }
  bool take_input_wait() { return std::exchange(input_wait_seen_, false); }
  bool take_probe() { return std::exchange(probe_seen_, false); }
  // Whether any of the three is waiting to be taken.
  bool waits_seen() const { return stop_seen_ || input_wait_seen_ || probe_seen_; }
  // Something in the stream this machine cannot run (spindle-synchronized motion): its line and
  // why. The program stops there.
  struct Unsupported {
    int line = 0;
    std::string why;
  };
  const std::optional<Unsupported>& unsupported() const { return unsupported_; }

  // The holds queued, by id; the task erases those it has answered.
  const std::map<std::uint32_t, HoldInfo>& holds() const { return holds_; }
  const HoldInfo* hold(std::uint32_t id) const;
  void erase_hold(std::uint32_t id) { holds_.erase(id); }
  void erase_tool_changes();
  void clear_holds() { holds_.clear(); }

  // M1 stops only while this is true (the panel's OPTIONAL_STOP switch; none wired: always).
  bool optional_stop() const { return optional_stop_; }
  void set_optional_stop(bool on) { optional_stop_ = on; }
  // The tool in the spindle when the program starts.
  void set_tool(int number) { tool_ = number; }

 private:
  std::deque<motion::Move> pending_;  // moves the queue had no room for yet
  int approach_moves_ = 0;
  std::uint64_t moves_queued_ = 0;
  std::uint64_t actions_queued_ = 0;
  bool stop_seen_ = false;
  bool optional_stop_ = true;
  bool input_wait_seen_ = false;
  bool probe_seen_ = false;
  std::optional<Unsupported> unsupported_;
  std::map<std::uint32_t, HoldInfo> holds_;
  int spindle_direction_ = 0;  // 1 cw, -1 ccw, 0 stopped
  double spindle_speed_ = 0;   // rpm
  bool mist_ = false;
  bool flood_ = false;
  int tool_ = 0;
  interp::MachineTracker tracker_;
  MessageHandler on_message_;
  // Where a move that goes into the queue starts: the wait for the spindle's speed before a
  // feed move, the outputs that go with it; `end_` moves to its end.
  void begin_move(motion::Move& next, int line);
  // G5, G5.1, G5.2: straight pieces within kSplineTolerance of the curve (feeder_spline.cpp).
  void queue_spline(const interp::NurbsFeed& spline, int line);
  // Queues a stop point (a zero dwell) where a spindle, coolant or tool event comes in the
  // program, for the task to flush the planner there: the path comes to rest at that point
  // instead of blending through it.
  void add_stop_point();
  // Queues an action (a zero dwell that does `action` at rest).
  void add_action(const motion::IoAction& action, int line);
  // Queues a hold the task answers, remembering what it waits for under its id.
  void add_hold(HoldInfo info, int line);
  // Queues M6's tool change to `number`: the traverse to the tool change position, the hold.
  void queue_tool_change(int number, int line, int before);
  // The spindle as the program sets it now.
  motion::IoAction spindle_action() const;
  const config::MachineConfig* machine_ = nullptr;
  // The machine's kinematics (null without a machine): TCP's frames, made once.
  std::shared_ptr<const motion::Kinematics> kins_;
  MessageHandler on_warning_;
  // Warns when the spindle's limits clamp the speed the program sets (once per speed).
  void check_speed(int line);
  double warned_rpm_ = -1;
  // The feed of the next feed move, machine units per second: F, or under G95 F per revolution
  // times the programmed spindle speed.
  double feed_per_second() const;
  // The spindle's speed as programmed (rpm): S, or under G96 the speed at `x` (machine
  // coordinates), within D.
  double nominal_rpm(double x) const;
  bool per_revolution_ = false;  // G95
  // Between START_SPEED_FEED_SYNCH and its stop: machine units per revolution (0: none).
  double per_rev_ = 0;
  // G96's D (maximum rpm; 1e30 when D is not given), 0 in G97.
  double css_max_rpm_ = 0;
  // M62/M63/M67 waiting for the next move.
  motion::SyncOutputs sync_{};
  // M3/M4 or S changed the spindle: the next feed move waits until it is at speed.
  bool need_at_speed_ = false;
  std::uint32_t next_hold_id_ = 1;
  // Where the last move queued ends (machine coordinates); where the program started until
  // then (machine zero when start_program() was not told).
  motion::AxisPose end_{};

  // M428 / M429: tool centre point control on a table-rotary machine (feeder_holds.cpp).
  // Switched with every rotary at 0, where the part's frame is the machine's; moves queued
  // while it is on carry Move::tcp. A program starts with it off.
  void switch_tcp(bool on, int line);
  // `machine` in the part's frame (`tcp`) or in the joints' from the other one.
  motion::AxisPose in_frame(const motion::AxisPose& machine, bool tcp) const;
  bool tcp_ = false;
  // G43, G43.1, G43.2, G49: the tool length offset's Z in force (machine units) goes with every
  // move (Move::tool_length); under TCP a change is refused where it would move a joint.
  void change_tool_length(int line);
  double tool_length_ = 0;
  // Under TCP the tool offset has no X or Y (the tip is turned about Z alone); false with
  // unsupported_ set (`what` at `line`) when it has.
  bool tcp_tool_offset_fits(int line, const std::string& what);

  // Path control mode and G64 P tolerance (machine units) as the interpreter last set them
  // (it starts in G64 and keeps its modes from one program to the next, as this feeder does).
  motion::Move::PathMode path_mode_ = motion::Move::PathMode::blend;
  double tolerance_ = 0;
  double merge_tolerance_ = 0;  // G64 Q
};

}  // namespace cncd::pipeline
