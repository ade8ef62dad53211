// The interpreter's private state and the helpers shared by its translation units (block
// execution, motion, canned cycles, control flow).
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "block.hpp"
#include "cncd/interp/interpreter.hpp"
#include "comp_state.hpp"
#include "failure.hpp"
#include "modal.hpp"
#include "parameters.hpp"
#include "parser.hpp"
#include "source.hpp"
#include "splines.hpp"
#include "tool_table.hpp"

namespace cncd::interp {

// Axis indexes into a Pose.
enum Axis : int { kX = 0, kY, kZ, kA, kB, kC, kU, kV, kW };
inline constexpr char kAxisLetters[kAxes + 1] = "xyzabcuvw";

enum class StraightKind : bool { traverse, feed };

// Values canned cycles remember between blocks while the cycle stays the motion mode.
struct CycleState {
  double r = 0;
  double z = 0;  // the plane's normal-axis value
  double p = 0;
  double q = 0;
  double i = 0;
  double j = 0;
  double k = 0;
  bool has_r = false, has_z = false, has_p = false, has_q = false;
  // LinuxCNC's "old Z": the drilling-axis position when a run of canned cycles starts, kept
  // (unconverted, whatever the plane) while the motion mode stays a canned cycle.
  double initial_level = 0;
};

// The Numeryx dialect's drilling state: the active cycle and its own variables (kept in the
// units they were given; switching units while a cycle is active is refused), the initial Z
// (Zi) and the polar positioning values.
struct NumeryxState {
  int cycle = 0;  // ten times the active cycle (730, 810 ..), 0 = g80
  double r = 0;
  double z = 0;
  double q = 0;
  double d = 0;  // dwell at the bottom, s
  bool has_r = false;
  bool has_z = false;
  bool has_q = false;
  bool incremental = false;  // the cycle's own g90/g91, for R and Z only
  bool has_zi = false;
  double zi = 0;  // the Z last read by a positioning block, in zi_units
  Units zi_units = Units::mm;
  double pole_i = 0;  // g10: pole, radius and angle (degrees), kept from block to block
  double pole_j = 0;
  double radius = 0;
  double angle = 0;
};

// An open Numeryx for loop.
struct ForFrame {
  int var = 0;
  double end = 0;
  double step = 1;
  std::int64_t offset = 0;  // the line after the for line
  int line_before = 0;
  int for_line = 0;
  bool skipped = false;  // the loop runs no pass: its next line ends it
};

// An open O-word block: if/elseif/else, while, do or repeat.
struct ControlFrame {
  OKind kind = OKind::none;
  std::string name;
  std::int64_t offset = 0;  // where the loop starts again (while: the while line itself)
  int line_before = 0;      // line number before that offset
  int remaining = 0;        // repeat: passes left
};

// Where a subroutine starts: the line after its "sub" line.
struct SubInfo {
  std::size_t source = 0;  // index into the open sources
  std::int64_t offset = 0;
  int line_before = 0;
  bool found_by_search = false;
  bool fanuc = false;  // a bare "O100" line: called by M98, ended by M99
};

// M70/M73: the modal state one call level saved, for M72 (and, M73, its return) to restore.
struct SavedModalState {
  bool valid = false;
  bool auto_restore = false;  // M73 in a subroutine: restored when it returns
  ModalState modal;
  Pose tool_offset{};        // G43.1's offsets
  bool g92_applied = false;  // #5210
  CompSide comp_side = CompSide::off;
};

struct CallFrame {
  std::string name;
  std::size_t source = 0;  // the caller's source
  std::int64_t return_offset = 0;
  int return_line = 0;
  std::size_t control_depth = 0;
  std::size_t nx_loop_depth = 0;              // Numeryx for loops open in the caller
  std::array<double, 30> saved_parameters{};  // the caller's #1-#30
  // M98: a Fanuc-style subprogram, which shares #1-#30 with its caller, ends with M99 and runs
  // `repeats_left` more times from `sub_offset` before it returns.
  bool fanuc = false;
  int repeats_left = 0;
  std::int64_t sub_offset = 0;
  int sub_line_before = 0;
  SavedModalState saved_modal;  // M70/M73 in this subroutine
  bool g7x = false;             // a G70-G72 profile: its return runs the cycle
};

class CanonSink;
struct G7xRun;  // cycle_g7x.cpp
namespace g7x {
struct Move;
}

inline constexpr int kG5xBase = 5221;  // G54 X; each system takes 20 parameters, R at +9
inline constexpr int kG92Base = 5211;

bool is_linear_axis(int axis);
void rotate_xy(Pose& pose, double degrees);
double unit_factor(Units from, Units to);
// An O-word name as messages write it: "o100", "o<probe>".
std::string o_label(const std::string& name);
// The O-word of a raw line, read without evaluating anything: kind none for a bare O-word,
// keywords matched as prefixes. A name that is a parameter or an expression (computed) is left
// to Interpreter::Impl::scan_o_line, which evaluates it.
enum class OScan { none, o_word, computed, unknown };
OScan scan_o_word(const std::string& line, std::string& name, OKind& kind);

// Where one canned cycle works: the plane axes, the drilling axis and its heights.
struct CycleGeometry {
  std::size_t a = 0;    // first plane axis
  std::size_t b = 1;    // second plane axis
  std::size_t c = 2;    // drilling axis
  double r = 0;         // R plane
  double bottom = 0;    // hole bottom
  double clear = 0;     // retract height at the end of each repeat
  double k = 0;         // G87 back-bore height
  double i = 0, j = 0;  // G87 offsets across the plane
  // Numeryx: the cycle has positioned itself (no move across at the current height first), and
  // the top pecks are measured from (R, below the R1 the tool feeds from); a dwell at the bottom
  // for every cycle (D), instead of LinuxCNC's P for the cycles that take one.
  bool position_first = true;
  std::optional<double> peck_top;
  std::optional<double> dwell;
};

// G76 as its words give it (cycle_g76.cpp): drive line (x0, z0) to Z z1, depths as radii.
struct ThreadingCycle {
  double x0 = 0, z0 = 0, z1 = 0;
  double pitch = 0, degression = 1, tan_q = 0;
  double i = 0, j = 0, k = 0;
  double taper = 0;  // E, along Z
  bool entry_taper = false, exit_taper = false;
  int spring_passes = 0;
};

struct Interpreter::Impl {
  explicit Impl(InterpOptions opts);

  // interpreter.cpp
  void reset_modal_state();
  Step step(CanonSink& sink);
  void emit_preamble();
  void run_line();
  void run_startup_code();
  // The dialect the first line names ("(dialect numeryx)"), else the machine's; the source is
  // read again from its start afterwards. Failure for a name that is no dialect.
  void detect_dialect();
  std::optional<InterpError> start_program(LineSource source);  // the file's or the text's
  InterpError make_error(const Failure& failure) const;

  // execute.cpp: one block in LinuxCNC's order of execution.
  void execute_block();
  void check_block() const;
  void check_supported_codes() const;

  // numeryx.cpp: the Numeryx dialect's blocks, cycles and loops.
  void check_numeryx_block() const;
  void numeryx_modes();
  void numeryx_motion();
  void define_numeryx_cycle(int code);
  void numeryx_drill();
  void set_zi();
  // for/next: true when the line is done (a for line, or a next that loops back).
  bool handle_numeryx_loop();
  void skip_numeryx_loop();
  bool axes_belong_elsewhere() const;
  bool axes_belong_to_non_modal() const;
  void check_word_users(int motion) const;
  void check_spindle_words(int motion) const;
  int motion_to_be() const;
  void do_comment();
  void halve_diameter_word();
  void set_diameter_mode(bool diameter);
  void do_spindle_mode();
  std::string substitute_parameters(const std::string& text) const;
  std::optional<double> predefined_parameter(std::string_view name) const;
  std::optional<double> ini_parameter(std::string_view name) const;
  void publish_parameters();
  void do_feed_mode();
  void set_feed_mode(FeedMode mode);
  void do_tool_and_spindle();
  void orient_spindle();
  void do_coolant_and_overrides();
  // io.cpp
  void do_io();
  void read_input_result();
  void do_user_m_code();
  void do_dwell();
  void do_modes();
  void do_non_modal();
  bool do_stop();
  void program_end_reset();

  // probe.cpp: G38.2-G38.5, their results and the probe file.
  void do_probe(int code);
  void read_probe_result();
  void track_standalone(const CanonOp& op);
  void sync_standalone();
  // (PROBEOPEN name) and (PROBECLOSE); true when the comment was one of them.
  bool probe_file_comment(const std::string& text);
  void close_probe_file();
  ProbeFileWriter& probe_writer();
  // Writes #5061-#5069 as a line of the open probe file; Failure when it cannot.
  void write_probe_line();

  // spindle_sync.cpp: G33, G33.1 and rigid tapping in canned cycles.
  void do_spindle_synced(int code);
  bool tapping_is_rigid(int code) const;
  void rigid_tap_hole(int code, const CycleGeometry& g, double a, double b, double& current_c);

  // cycle_g76.cpp: the lathe threading cycle.
  void check_threading_words() const;
  ThreadingCycle read_threading_cycle() const;
  void threading_pass(const ThreadingCycle& t, double depth);
  void do_threading_cycle();

  // motion.cpp
  void do_motion();
  Pose target_from_words() const;
  void straight(StraightKind kind, const Pose& end);
  void arc(bool clockwise, const Pose& end);
  void arc_center(bool clockwise, PlanePoint start, PlanePoint end, double& c1, double& c2) const;
  void arc_feed_rate(bool clockwise, int turns, const Pose& start, PlanePoint c, const Pose& end);
  void set_inverse_time_rate(double length);
  void emit_straight(StraightKind kind, const Pose& end);

  // offsets.cpp, setup_codes.cpp
  void do_g10();
  void set_coord_system_data(int l, int system);
  void set_tool_data(int l, int tool);
  Pose read_offset_parameters(int base) const;
  // Writes the axes in `axes` (bit 0 = X) of an offset in program units to the parameters
  // from `base` on, in machine units: all of them, or (Failure) none when one is not storable.
  void write_offset_parameters(int base, const Pose& offset, std::uint32_t axes);
  // Where the block names `letter`, else its group 0 code (G10, G92, G28.1 ...).
  int word_column(char letter) const;
  double to_machine_units(double program_value) const;
  void do_g92(int code);
  void do_home(int code);
  void select_coord_system(int index);
  void select_coord_system_quiet(int index);
  void emit_g5x();
  void emit_g92();
  void load_coord_system(int index);
  void change_units(Units units);
  void apply_tool_length(int code);
  Pose table_offset(const ToolEntry& entry) const;
  Pose machine_to_program(const Pose& machine) const;
  Pose program_to_machine(const Pose& program) const;
  // splines.cpp: G5, G5.1, and G5.2 .. G5.3.
  void do_spline(int code);
  void do_nurbs_point();
  void close_nurbs();
  // cycles.cpp
  void do_canned_cycle(int code);
  void check_cycle_plane_words() const;
  void cycle_body(int code, const CycleGeometry& g, double a, double b, double& current_c);
  // cycle_g7x.cpp: G70, G71, G72 and their .1 and .2 forms.
  static bool is_g7x_code(int code);
  void do_g7x(int code);
  bool g7x_capture(const CanonCommand& command);  // a move of the profile, kept
  bool reading_g7x_profile() const;
  void finish_g7x();
  void emit_g7x_move(const G7xRun& run, const g7x::Move& move);
  // control.cpp: O-words.
  void handle_o_word();
  void do_call();
  void do_return(bool has_value, double value);
  // fanuc_subs.cpp: M98 and M99. True when the line was an M98 call or an M99 return.
  bool handle_fanuc_codes();
  void do_m98();
  void do_m99();
  bool find_fanuc_sub(const std::string& name);
  // modal_state.cpp: M70-M73.
  void do_modal_state(int code);
  void check_modal_state_line() const;
  bool block_has_other_words() const;
  SavedModalState& saved_modal_state();
  void restore_modal_state(const SavedModalState& saved);
  void restore_modes(const SavedModalState& saved);
  void restore_coolant(const ModalState& saved);
  void restore_overrides(const ModalState& saved);
  // Before a subroutine returns (endsub, return, M99): the state its M73 saved comes back.
  void auto_restore_modal_state();
  // Reads on to the line of `name` with one of `stops` (returned); line_ holds it.
  OKind skip_block(const std::string& name, std::initializer_list<OKind> stops);
  // `closing_line`: set to the closing '%' line when the search stopped there.
  bool find_indexed_sub(const std::string& name, std::int64_t offset, int& closing_line);
  // o_word_scan.cpp: scan_o_word, with a computed name evaluated with today's parameters and
  // an unknown keyword refused, as rs274 refuses it in the lines it skips or searches.
  bool scan_o_line(const std::string& line, std::string& name, OKind& kind);
  // program_delimiters.cpp. True when line_ is a '%' that opens or (ended_ set) closes the
  // program.
  bool delimiter_line();
  // line_, read while seeking, is the program's closing '%'.
  bool at_closing_percent() const;
  // Seeking `name` (a sub, else an if or loop) met the closing '%' at `line`: the program
  // ends there, as in rs274 (FINISH, then the error).
  [[noreturn]] void end_at_closing_percent(const std::string& name, bool sub, int line);
  // After M2 in a program opened with '%': rs274's comment when no '%' closes it.
  void check_percent_after_end();
  bool find_sub(const std::string& name);
  // The sub (an M98 subprogram when `fanuc`) named `name`, sought when not seen yet; rs274's
  // error when it is nowhere.
  const SubInfo& known_sub(const std::string& name, bool fanuc);
  void skip_loop_end(const ControlFrame& frame);
  std::string label_error(const char* what) const;
  LineSource& source() { return sources_.back(); }

  // emit helpers
  // Every canonical command leaves here, with the current line; one carrying a number that is
  // not finite (a position that overflowed) fails the block instead.
  // Assigned over the last command: the same alternative again is assigned field by field,
  // without building and destroying a whole CanonOp.
  template <class Op>
  void emit(Op&& op) {
    command_.line = current_line_;
    command_.op = std::forward<Op>(op);
    emit_command(command_);
  }
  void emit_command(const CanonCommand& command);  // held back behind queued moves, or sent
  void send_command(const CanonCommand& command);
  // Jumps back to the start of a loop; fails once loops have run max_loops_without_motion
  // times in a row without a move or dwell (an endless loop that would never end).
  void loop_back(std::int64_t offset, int line_before);
  void emit_comment(const std::string& text);

  double to_program_units(double machine_value) const;
  Units tool_table_units() const;

  InterpOptions options_;
  Dialect dialect_ = Dialect::linuxcnc;  // in effect for the open program
  Parameters parameters_;
  BlockParser parser_{parameters_};
  ToolTable tools_;
  Block block_;
  std::string line_;
  std::vector<LineSource> sources_;  // back() is being read; subroutine files are pushed
  std::string program_name_;
  CanonSink* sink_ = nullptr;
  CanonCommand command_;
  std::optional<InterpError> error_;
  std::optional<InterpError> config_error_;  // unreadable parameter file or tool table
  bool parameter_file_refused_ = false;      // never written then
  std::vector<std::string> load_warnings_;   // parameter file or tool table not there yet
  int current_line_ = 0;
  std::uint64_t loops_without_motion_ = 0;
  bool preamble_done_ = false;
  bool ended_ = false;
  bool mdi_ = false;           // executing MDI: the end of the text ends it, no M2 or % needed
  bool text_seen_ = false;     // a line that is not blank has been read: no '%' opens now
  bool seen_percent_ = false;  // the program opened with '%': the next '%' line ends it
  bool resend_g5x_ = false;    // set_coord_system_origin() changed the active system's origin
  bool resend_g92_ = false;    // restore_persistent_parameters() may have changed the G92 offset
  bool resend_tool_offset_ = false;  // set_tool_in_spindle() changed the tool length offset

  ModalState modal_;
  int previous_motion_ = -1;  // the motion mode before the current block
  CycleState cycle_;
  CompState comp_;
  struct Comp;  // cutter_comp.hpp
  SplineState spline_;
  std::shared_ptr<G7xRun> g7x_;  // a G7x cycle reading its profile
  NumeryxState nx_;
  std::vector<ForFrame> nx_loops_;
  int nx_cycle_distance_ = -1;  // this block's g90/g91 that belongs to the drilling cycle
  Pose pos_{};                  // current position: program coordinates, program units
  Pose g5x_offset_{};           // active coordinate system origin, program units
  Pose g92_offset_{};
  double rotation_deg_ = 0;
  Pose tool_offset_{};  // tool length offset, in the units it was set in (as LinuxCNC keeps it)
  Pose tool_offset_machine_{};  // the same in machine units, for status
  int tool_in_spindle_ = 0;
  int tool_prepped_ = -1;
  std::vector<ControlFrame> control_;
  std::vector<CallFrame> calls_;
  SavedModalState saved_modal_top_;  // M70/M73 in the main program
  std::unordered_map<std::string, SubInfo> subs_;
  std::int64_t line_offset_ = 0;  // offset of the line being executed
  int line_before_ = 0;           // line number before it
  bool input_pending_ = false;    // an M66 ran: #5399 gets its answer before the next line
  bool input_digital_ = true;     // the M66 was for a digital input
  // A G38.n ran: #5061-#5070 and the position get its result before the next line.
  bool probe_pending_ = false;
  Pose probe_end_{};  // its programmed end
  // LinuxCNC's standalone canon (rs274) keeps a program position of its own: the end of the
  // last move, shifted by each change of the G5x and G92 offsets (leaving out the XY rotation)
  // and scaled by each change of units. After a probe, its interpreter takes that position.
  struct StandaloneCanon {
    Pose pos{};
    Pose g5x{};
    Pose g92{};
    Units units = Units::mm;
  };
  StandaloneCanon standalone_;
  // (PROBEOPEN name): the file the probe results go to. The writer opens (and empties) it with
  // the first result, so that a run without a machine (a check) leaves it as it was.
  std::optional<ProbeFileTarget> probe_target_;
  bool probe_opened_ = false;
  std::shared_ptr<ProbeFileWriter> probe_writer_;
  std::shared_ptr<const SubroutineIndex> sub_index_;  // of the program file open()
  std::filesystem::path program_dir_;  // of the program file open(); empty for MDI and text
  double last_value_ = 0;              // #<_value>
  bool value_returned_ = false;        // #<_value_returned>
  std::string o_scan_name_;            // scratch for skipping lines
};

}  // namespace cncd::interp
