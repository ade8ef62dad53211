// The task layer: machine state (estop/off/on), program execution, and the glue from the
// interpreter's canonical commands to the motion controller's queue.
//
// Single-threaded: every method is called from the daemon's main loop thread; the long work
// of program.open and the time estimate run on threads of their own (program_open.hpp,
// plan_estimate.hpp) on copies of what they need.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/motion/controller.hpp"
#include "cncd/pipeline/program_runner.hpp"
#include "event_log.hpp"
#include "job_history.hpp"
#include "panel_rules.hpp"
#include "persist.hpp"
#include "plan_estimate.hpp"
#include "probe_writer.hpp"
#include "program_open.hpp"
#include "program_preview.hpp"
#include "task_outcome.hpp"
#include "task_report.hpp"
#include "user_m.hpp"

namespace cncd::daemon {

class Task {
 public:
  // `answers` receives the outcomes of machine.on, program.open, program.abort and mdi.execute
  // once they are known.
  Task(const config::MachineConfig& config, EventLog& events, TaskAnswers& answers);
  ~Task();
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  // Checks the files read at start: the parameter file and tool table (when they exist) and
  // [TRAJ] POSITION_FILE, whose joint positions the next start() begins at. Returns "" or
  // "FILE:LINE: what is wrong"; after an error shutdown() leaves those files alone.
  std::string load_files();
  // Starts the servo thread. Returns "" or an error.
  std::string start();
  // Stops motion under control and the servo thread, then saves the parameter file and the
  // joint positions to [TRAJ] POSITION_FILE.
  void shutdown();

  // Each command throws TaskError when refused in the current state, and (kind fault) when the
  // machine does not do it: reset with the estop input asserted, homing the servo thread
  // refuses (task_machine.cpp).
  void estop();
  void reset();
  // Enables the drives. The machine counts as on once the drivers have had the time to report
  // a drive that does not answer or has faulted (MotionController::feedback_deadline_ns):
  // returns true when the answer, under `token`, is posted then (poll()); with token 0 (a
  // batch) it waits here. Throws a fault naming the joint, drive and reason when the machine
  // does not come on.
  bool machine_on(std::uint64_t token);
  void machine_off();
  void home(std::uint32_t joint_mask);
  // Opens a program once it has passed the check of the whole program (program_open.hpp),
  // which runs on a worker thread meanwhile; the answer under `token` is posted then: the
  // program's path, or why it was refused (cannot be read, leaves the soft limits, stopped
  // by the interpreter) or cancelled (a newer open, an estop, shutdown). Refuses at once
  // (TaskError) while a program or MDI block runs or the machine jogs or homes.
  void open_program(const std::string& path, std::uint64_t token);
  // program.preview: the open program's toolpath at `tolerance` (0: the machine's default),
  // answered under `token` once worked out in the background (task_open.cpp).
  void preview_program(double tolerance, std::uint64_t token);
  // Runs the open program; from_line > 1 runs it from that line (see ProgramRunner::skip_to);
  // `step` runs its first line only, as program.step does.
  void run_program(int from_line = 0, bool step = false);
  // Runs one more line of the program (from idle: the first), then pauses; resume runs on.
  void step();
  // The feed hold; what it waits for first (a thread's or a tap's end), if anything.
  PauseWaitReport pause();
  void resume();
  // Stops under control; the answer under `token` (if not 0) is posted once at rest.
  void abort(std::uint64_t token = 0);
  // Jogs of one axis (config::axis_index), velocities in machine units per second (see
  // MotionController::jog_start); refused while a program or MDI block runs (task_manual.cpp).
  void jog_start(int axis, double velocity);
  void jog_increment(int axis, double distance, double velocity);
  void jog_stop(int axis);
  // Overrides, ratios with 1.0 = 100 % (override_methods.cpp checks their ranges). Feed and
  // rapid reach the servo thread at once, as pause does, and act on the move under way; the
  // spindle override scales the commanded spindle speed.
  void set_feed_override(double ratio);
  void set_rapid_override(double ratio);
  void set_spindle_override(double ratio);
  // The operator has put in `tool`, the one a running program's M6 waits for: the program goes
  // on. Throws TaskError: wrong_state when no tool change is waited for, bad_value when the
  // change waiting is for another tool.
  void tool_change_done(int tool);
  // The operator ends the program's wait of `kind` ("input": an M66 goes on as on its
  // timeout; "spindle_at_speed": the feed goes on while the spindle turns as told).
  void wait_done(const std::string& kind);
  // At the end of a run: the tool put back as the machine has it (task_io.cpp).
  void untake_tool_changes(bool ended_as_written);
  // Executes one MDI block; the answer under `token` is posted when it has finished.
  void mdi(const std::string& line, std::uint64_t token);

  // Each program run goes to `history` (null: none is kept); it must outlive the task.
  void record_jobs(JobHistory* history) { jobs_ = history; }
  // jobs.history (stats false) and jobs.stats: answered later under `token` (task_jobs.cpp).
  void ask_jobs(std::uint64_t token, bool stats, double since, int limit);

  // Feeds the planner from the interpreter, notices the end of a program, logs servo events.
  // Called every loop iteration.
  void poll();
  // True while a program is being fed or checked for opening, or motion is under way: the
  // loop should poll often.
  bool busy() const;

  // Tool table and coordinate systems (task_setup.cpp). The setters throw TaskError while a
  // program or MDI command runs, and when the file cannot be written (nothing changes then).
  std::vector<interp::ToolEntry> tools() const;
  std::optional<interp::ToolEntry> find_tool(int number) const;
  // Replaces or adds the entry and rewrites [EMCIO] TOOL_TABLE atomically.
  void set_tool(const interp::ToolEntry& entry);
  OffsetsReport offsets() const;
  // Sets the origin of coordinate system `system` (1..9 = G54..G59.3) for the axes in `axes`
  // (bit 0 = X), machine units, as G10 L2 does, and saves the parameter file.
  void set_offsets(int system, const interp::Pose& origin, std::uint32_t axes,
                   std::optional<double> rotation_deg);

  TaskStatus status() const;
  // The sim driver start() made (sim.set sets its signals), null when the machine has none.
  drivers::SimDriver* sim_driver() const { return started_ ? sim_ : nullptr; }
  // The servo thread's cycle counter: it advances while the servo loop is alive.
  std::uint64_t servo_heartbeat() const { return motion_.status().sequence; }
  // One line for systemd's STATUS=, e.g. "on, running part.ngc line 12".
  std::string summary() const;

 private:
  void feed();
  void start_run(Mode mode, const motion::Status& status);
  // Changes exec_, keeping count of the time spent paused (task_status.cpp).
  void set_exec(ExecState next);
  // Sets the program's remaining_s and estimated_s (none when unknown) and why
  // (task_status.cpp).
  void time_estimate(std::uint64_t moves_done, ProgramReport& out) const;
  // Time the current run has spent moving: since it started, without its pauses.
  double moving_s() const;
  // Servo periods run since the servo thread had run `cycles`, in seconds.
  double servo_seconds_since(std::uint64_t cycles) const;
  void drain_servo_events();
  // The holds the path waits in (task_io.cpp): a tool change waits for tool_change_done(), a
  // user M code runs and its end releases the path. Returns false when the run has ended.
  bool poll_holds(const motion::Status& status);
  // A probe file line that could not be written ends the run with the error at its line
  // (task_io.cpp); between runs it goes to the event log.
  void poll_probe_file();
  // What the path waits for, in words (task_io.cpp).
  WaitReport wait_report(const motion::Status& status) const;
  // Answers the machine.on requests waiting for the drives (task_machine.cpp).
  void confirm_machine_on(const motion::Status& status);
  std::chrono::steady_clock::duration on_check_time() const;
  void wait_servo_periods(int periods) const;
  // Rewrites the parameter file and the tool table where they differ from what the interpreter
  // holds (G10, G92, G5x, offsets.set). One that cannot be written is put back in the
  // interpreter as its file holds it, so that what is in force is what a restart would load.
  // Returns "" or what could not be written (task_setup.cpp).
  std::string save_setup_files();
  // [TRAJ] POSITION_FILE (task_persist.cpp). The marker beside it says, while cncd runs, that
  // the file is kept up to date and the final save has not been made yet.
  void mark_running();
  // Saves the joint positions when the machine comes to rest, twice more while it settles,
  // and every two seconds while it moves, when they changed: a crash loses little.
  void keep_positions(const motion::Status& status);
  // Writes the joints' actual positions unless the file already holds them: "" or an error.
  std::string write_positions(const motion::Status& status);
  // The final save at shutdown, which also removes the marker.
  void save_positions();
  // Each joint's limits, for the position file (task_persist.cpp).
  std::vector<JointRange> joint_ranges() const;
  // `line`: the program line an error is at, 0 when none.
  void finish_program(const std::string& result, const std::string& error, int line = 0);
  // The job history's row of a run: begun as it starts, ended with its result (task_jobs.cpp).
  void begin_job();
  void end_job(const std::string& result, const std::string& error, int line);
  std::optional<double> whole_estimate() const;
  // The job history's answers and reports (task_jobs.cpp).
  void poll_jobs();
  // The pending open's check has ended (task_open.cpp).
  void finish_open(OpenOutcome outcome);
  // Answers the pending open, if any, with a cancelled error and `why`.
  void cancel_open(const std::string& why);
  bool all_homed(const motion::Status& status) const;
  // The servo status when the machine may run a program or MDI block: on, at rest and homed
  // (unless NO_FORCE_HOMING); throws TaskError naming what is missing `before` that.
  motion::Status ready_status(const char* before) const;
  // Ends the run at the runner's error.
  void finish_with(const pipeline::ProgramRunner::Error& error);

  const config::MachineConfig& config_;
  EventLog& events_;
  TaskAnswers& answers_;
  motion::MotionController motion_;
  // Before interp_, which writes through it.
  std::shared_ptr<QueuedProbeWriter> probe_writer_ = std::make_shared<QueuedProbeWriter>();
  std::unique_ptr<interp::Interpreter> interp_;
  // Reads the program (or MDI block) into motion_'s queue.
  std::unique_ptr<pipeline::ProgramRunner> runner_;
  std::vector<interp::ToolEntry> saved_tools_;  // the tool table as its file holds it
  std::vector<double> saved_parameters_;        // the persistent parameters as the file holds them
  ExecState exec_ = ExecState::idle;
  Mode mode_ = Mode::manual;
  std::uint64_t mdi_token_ = 0;
  std::vector<std::uint64_t> abort_tokens_;
  std::string program_path_;
  std::uint64_t program_lines_ = 0;
  std::shared_ptr<const interp::SubroutineIndex> program_subs_;  // of the open program
  // The dialect the open program is read in; with none open, the machine's (MDI's).
  interp::Dialect program_dialect_ = interp::Dialect::linuxcnc;
  std::uint64_t moves_done_base_ = 0;    // motion's completed-move count when it started
  std::uint64_t actions_done_base_ = 0;  // motion's completed-action count when it started
  std::uint64_t moves_completed_ = 0;    // moves the last finished run completed
  std::string last_result_;              // "done" | "aborted" | "error" | "" (never ran)
  std::string last_error_;
  std::uint64_t path_errors_base_ = 0;  // motion's path error count when the run started
  // M66 read: the runner waits to read on until the machine has waited and #5399 holds its
  // answer (motion's count of ended input waits passes input_waits_seen_).
  std::uint64_t input_waits_seen_ = 0;
  // G38.x read: likewise until the probing move is over (motion's count of ended probing moves
  // passes probes_seen_) and #5061-#5070 hold where it tripped.
  std::uint64_t probes_seen_ = 0;
  UserMProcess user_m_;            // the user M code running, if any
  std::uint32_t user_m_hold_ = 0;  // the hold it answers
  bool stepping_ = false;          // program.step: one line, then pause
  std::chrono::steady_clock::time_point started_at_{};
  double elapsed_s_ = 0;
  // The run on the servo clock: servo periods since program.run (rt.cycles) x the period. Falls
  // behind elapsed_s_ only when the servo thread stalled and skipped periods.
  std::uint64_t started_cycles_ = 0;
  double motion_s_ = 0;
  PlanEstimator estimator_;  // the open program's running time, worked out in the background
  bool from_top_ = false;    // the run started at the program's first line
  int run_from_line_ = 0;    // run from line: the line it started at
  int tool_at_start_ = 0;    // the tool in the spindle when the run started
  // Run from line with a traverse to the line's start: the moving time when it ended.
  std::optional<double> approach_done_s_;
  std::chrono::steady_clock::time_point paused_since_{};
  double paused_s_ = 0;         // time the current run has spent paused, up to paused_since_
  bool files_corrupt_ = false;  // load_files() failed: keep them as they are for the user
  bool started_ = false;        // motion started: its joint positions are worth saving
  std::vector<std::uint64_t> on_tokens_;  // machine.on answers waiting for the drives
  std::chrono::steady_clock::time_point on_check_until_{};
  // Where the joints started: "clean" (the position file of an orderly shutdown), "unclean"
  // (the positions last saved by a run that did not shut down) or "none".
  std::string position_restored_ = "none";
  std::string positions_written_;  // what this run last wrote to the position file
  std::chrono::steady_clock::time_point next_position_save_{};
  std::optional<std::chrono::steady_clock::time_point> settle_save_at_;
  int settle_saves_left_ = 0;
  bool was_moving_ = false;
  bool position_save_failing_ = false;  // the failure has been logged; quiet until a success
  struct PendingOpen {
    std::uint64_t job = 0;
    std::uint64_t token = 0;
    std::string path;
    interp::Pose start{};  // where the machine stood: the check and the estimate start there
  };
  std::optional<PendingOpen> opening_;  // program.open waiting for its check
  bool was_estop_ = true;               // the machine was in estop at the last poll()
  drivers::SimDriver* sim_ = nullptr;   // among the drivers motion_ runs
  // Every driver motion_ runs, for the notices they give (a pendant unplugged): events.
  std::vector<drivers::Driver*> drivers_;
  // machine.on from the panel: its outcome is an event, not an answer.
  static constexpr std::uint64_t kPanelToken = ~std::uint64_t{0};
  // The panel ([PANEL], task_panel.cpp): each poll() acts on its presses, switches, jog
  // buttons and knobs as PanelStatus shows them, and lights its lamps.
  void poll_panel(const motion::Status& status);
  void panel_press(config::PanelInput input);
  void panel_door(const motion::Status& status);
  void panel_switches(const motion::Status& status);
  void panel_jogs(const motion::Status& status);
  void panel_knobs(const motion::Status& status);
  void panel_lights(const motion::Status& status);
  // Why a jog button cannot jog `axis` now ("" when it can): one hand on the machine.
  std::string panel_jog_refusal(const motion::Status& status) const;
  bool panel_wired(config::PanelInput input) const;
  // The input is wired and on.
  bool panel_level(config::PanelInput input, const motion::Status& status) const;
  // The DOOR input is wired and open: programs, MDI and resume are refused.
  bool door_open(const motion::Status& status) const;
  void refuse_if_door_open() const;
  PanelReport panel_report(const motion::Status& status) const;
  PanelMemory panel_;
  // Client jogs under way (bit = axis) and who started the last: the panel's jog buttons are
  // refused naming them.
  std::uint32_t client_jog_axes_ = 0;
  std::string client_jog_by_;
  // The servo cycle a client's last jog was started at: the status of the cycles after it
  // shows the jog (the command is taken within one period).
  std::uint64_t client_jog_cycle_ = 0;
  static constexpr std::uint64_t kJogSeenCycles = 3;
  // Who jogs now, if anyone: the panel or a client (task_manual.cpp).
  std::optional<ManualHolder> manual_holder(const motion::Status& status) const;
  // Throws TaskError (busy) when a client may not jog now: a program runs, the panel or
  // another client jogs.
  void client_may_jog() const;
  void client_jogs(int axis);
  // The name a client's jog is held by: who the request comes from.
  std::string jog_actor() const;
  // Run from line: the index in the estimate of the line's first move (time_estimate()).
  struct FirstMove {
    std::shared_ptr<const std::vector<std::int32_t>> lines;  // the estimate's move lines
    int line = 0;
    std::uint64_t index = 0;
  };
  mutable FirstMove first_move_;
  ProgramOpener opener_;
  ProgramPreviewer previewer_;
  JobHistory* jobs_ = nullptr;
  std::uint64_t job_ = 0;  // the run's handle in jobs_, 0: none
};

}  // namespace cncd::daemon
