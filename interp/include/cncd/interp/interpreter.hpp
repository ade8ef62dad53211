// The RS274NGC interpreter. Single-threaded: one thread owns an Interpreter. Reads the program
// incrementally (memory does not grow with program length) and emits canonical commands to a
// CanonSink block by block.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "cncd/interp/canon.hpp"
#include "cncd/interp/probe_file.hpp"
#include "cncd/interp/to_machine.hpp"
#include "cncd/interp/tool_entry.hpp"  // MachineTracker, which every user of the stream needs

namespace cncd::interp {

struct InterpError {
  std::string file;
  int line = 0;    // 1-based, 0 = not tied to a line
  int column = 0;  // 1-based, 0 = unknown
  std::string message;
  // "FILE:LINE:COLUMN: message" (column left out when 0)
  std::string to_string() const;
};

// Which reading of the program: LinuxCNC's RS274NGC, or the Numeryx (Ncplus) drilling dialect
// of its application note An-101 (cycle heights R1 = R + clearance and Zi, for/next loops,
// gil(), polar g10). One core; the dialect changes the cycles and that syntax only.
enum class Dialect : std::uint8_t { linuxcnc, numeryx };
// "linuxcnc" or "numeryx".
const char* dialect_name(Dialect dialect);
// The dialect a name gives (any case, blanks around it ignored), or nothing.
std::optional<Dialect> parse_dialect(std::string_view name);

struct InterpOptions {
  Units machine_units = Units::mm;       // units of the machine (INI LINEAR_UNITS)
  std::filesystem::path parameter_file;  // empty = none
  std::filesystem::path tool_table;      // empty = none
  // Units the tool table is written in (LinuxCNC: the machine's units; its standalone rs274
  // reads tables as inches). Unset = machine_units.
  std::optional<Units> tool_table_units;
  std::vector<std::filesystem::path> subroutine_path;
  // Directories searched in order for the user M codes M100-M199: an executable regular file
  // named exactly M100 .. M199 (LinuxCNC's [DISPLAY] PROGRAM_PREFIX, then [RS274NGC]
  // USER_M_PATH). A user M code found nowhere is an error ("Unknown m code used: M101").
  std::vector<std::filesystem::path> user_m_path;
  std::string startup_code;   // RS274NGC_STARTUP_CODE, run before the program
  bool block_delete = false;  // skip lines starting with '/'
  // [RS274NGC] DIALECT. A program's first line (after a '%' line) may name another one:
  // "(dialect numeryx)" or "(dialect linuxcnc)".
  Dialect dialect = Dialect::linuxcnc;
  // false: `dialect` holds whatever the first line says (cncd-check --dialect, to compare the
  // two readings of one program).
  bool dialect_from_first_line = true;
  // [RS274NGC] NUMERYX_CLEARANCE, machine units: R1 = R + clearance in the Numeryx dialect.
  // Unset: the note's 1 mm in a G21 program, 0.04 in in a G20 one.
  std::optional<double> numeryx_clearance;
  // [EMCIO] TOOL_CHANGE_QUILL_UP: M6 first raises Z to machine zero (a traverse, as LinuxCNC's
  // interpreter emits it); TOOL_CHANGE_WITH_SPINDLE_ON: M6 leaves the spindle turning.
  bool tool_change_quill_up = false;
  bool tool_change_with_spindle_on = false;
  // O-word loop iterations in a row without a move or dwell before the program is rejected as
  // an endless loop (LinuxCNC would spin forever).
  std::uint64_t max_loops_without_motion = 1'000'000;
  // [RS274NGC] RIGID_TAPPING: G84 and G74 tap in step with the spindle (StartSpeedFeedSynch,
  // RigidTap, StopSpeedFeedSynch per hole, the pitch F in G95 and F/S in G94) instead of
  // LinuxCNC's floating-holder cycle; in the Numeryx dialect g84 (its g74 always is). Whether
  // the machine can (spindle position feedback) is for its configuration to say.
  bool rigid_tapping = false;
  // [CNCD] PROBE_DIR: the directory (PROBEOPEN name) files go to. Empty: the program's
  // directory, or for MDI the first subroutine_path directory (a library use without a
  // machine configuration).
  std::filesystem::path probe_dir;
  // Files a probe file may never be, besides parameter_file and tool_table ([TRAJ]
  // POSITION_FILE).
  std::vector<std::filesystem::path> state_files;
  // Who opens and writes the probe file; null = the interpreter's thread (SyncProbeWriter).
  std::shared_ptr<ProbeFileWriter> probe_writer;
  // The machine's INI, for #<_ini[SECTION]KEY>: the text of KEY in SECTION (names as written
  // there, matched exactly), or nothing. Null: no INI, and no such parameter exists.
  // M428/M429, the TCP switch of a table-rotary machine: where the machine's position (machine
  // coordinates and units) lies in the frame the switch leads to (the part's for M428, the
  // joints' for M429). Null: the position stays as it is (no such machine, or rs274's canon).
  std::function<Pose(const Pose& machine, bool tcp_on)> tcp_switch;
  std::function<std::optional<std::string>(const std::string& section, const std::string& key)>
      ini_value;
};

// Where each o<name> sub of a program file is defined, found by reading the file once
// (index_program()), so that a call of a subroutine defined far below need not read its way
// there while the machine runs.
struct SubroutineIndex {
  struct Definition {
    std::int64_t offset = 0;  // of the sub's line
    int line = 0;             // its number
  };
  // By lower-case name (digits for o123), in file order.
  std::unordered_map<std::string, std::vector<Definition>> definitions;
  // The O-word lines whose name is a parameter or an expression (o#1 sub, o[#2*10] endsub ...),
  // in file order: their name is known only when the search that passes them evaluates it.
  std::vector<Definition> computed;
  // The '%' line that closes a program opened with '%' (offset -1: none). The lines after it
  // are no part of the program: nothing there is indexed.
  Definition closing_percent{-1, 0};
  std::uint64_t lines = 0;  // lines of the file, a last one without a newline counted too
  // More definitions and computed lines than this refuse the program: the index must stay small.
  static constexpr std::size_t kMaxDefinitions = 100'000;
};

// Reads `program` through once, as a program check does (on a thread where waiting is
// harmless): its subroutine definitions and lines, or the error that refuses it (it cannot be
// read, a line is too long). `cancelled`, when given, is asked every few thousand lines; a
// cancelled read returns an error saying so.
std::optional<InterpError> index_program(const std::filesystem::path& program, SubroutineIndex& out,
                                         const std::function<bool()>& cancelled = {});

// What the interpreter holds between blocks, for status displays. Lengths in machine units,
// angles in degrees. The interpreter reads ahead of motion: during a program this is the state
// after the last block it has read, not the one the machine is executing.
struct InterpState {
  int line = 0;  // line of the block last executed
  // LinuxCNC's active_g_codes: ten times the code (G59.3 -> 593), -1 = none; index 0 holds
  // the line, 1 motion, 2 the last block's group 0 code, 3 plane, 4 cutter compensation,
  // 5 units, 6 distance mode, 7 feed mode, 8 coordinate system, 9 tool length offset,
  // 10 retract mode, 11 path control, 12 rotation (G68, unsupported), 13 spindle mode,
  // 14 arc distance mode, 15 lathe diameter mode, 16 G92.3 while G92 offsets are kept.
  std::array<int, 17> gcodes{};
  // LinuxCNC's active_m_codes: 0 line, 1 the last block's stop code, 2 spindle, 3 the last
  // block's tool change, 4 mist (M9 when no coolant), 5 flood, 6 overrides, 7 adaptive feed,
  // 8 feed hold, 9 unused (-1).
  std::array<int, 10> mcodes{};
  int coord_system = 1;  // 1..9 = G54..G59.3
  Pose g5x_offset{};
  double rotation_deg = 0;  // XY rotation of the coordinate system (G10 L2 R)
  Pose g92_offset{};
  Pose tool_offset{};
  int tool_in_spindle = 0;
  int tool_prepared = -1;  // -1 = none
  double feed_rate = 0;    // program units per minute (F)
  double speed = 0;        // rpm (S)
};

class Interpreter {
 public:
  explicit Interpreter(InterpOptions options = {});
  ~Interpreter();
  Interpreter(const Interpreter&) = delete;
  Interpreter& operator=(const Interpreter&) = delete;

  // Tells the interpreter where the machine is, in the machine's units and program
  // coordinates of the current coordinate system (what a machinist sees on the DRO).
  void set_position(const Pose& position);
  // Tells the interpreter where the machine is in machine coordinates and the machine's units
  // (what the servo loop reports); the interpreter applies its own offsets and units. Call it
  // after open(), whose reset may change them.
  void set_machine_position(const Pose& machine);
  // Replaces InterpOptions::tcp_switch (the caller that runs the program knows the TCP state).
  void set_tcp_switch(std::function<Pose(const Pose& machine, bool tcp_on)> tcp_switch);

  // Opens a program file and resets to the start-of-program modal state. With `index` (of
  // this file, index_program()), a call finds a subroutine defined below it there rather than
  // by reading on; a definition no longer where the index says is an error (the file changed).
  std::optional<InterpError> open(const std::filesystem::path& program,
                                  std::shared_ptr<const SubroutineIndex> index = nullptr);
  // Opens one MDI block: the modal state stays as the last line or program left it, and the
  // end of the text ends it (no M2 or % needed).
  std::optional<InterpError> open_mdi(std::string line);
  // Opens a program held in memory (tests); `name` is used in messages.
  std::optional<InterpError> open_string(std::string text, std::string name = "<mdi>");

  enum class Step { block, end, error };
  // Executes the next block, emitting its canonical commands to `sink`. Returns `end` after
  // M2/M30/% or end of file, `error` when the block is rejected (see error()).
  Step step(CanonSink& sink);
  const std::optional<InterpError>& error() const;
  // Why the parameter file or the tool table could not be loaded at construction, if so.
  const std::optional<InterpError>& load_error() const;
  // A parameter file or tool table that does not exist yet: the defaults (an empty table) are
  // used, as LinuxCNC does; one line per file, naming it.
  const std::vector<std::string>& load_warnings() const;
  // The answer to the last M66 (WaitInput): the input's value (digital 0 or 1, analog its
  // value) or -1 when the wait timed out. #5399 takes it. The caller (the daemon's task) stops
  // calling step() after a WaitInput until the machine has waited, then calls this before the
  // next step(). Without it, #5399 reads as LinuxCNC's standalone interpreter gives it: for a
  // digital input 1 if #5399 was not 0 and 0 if it was, for an analog input unchanged. A
  // value that is not finite is taken as -1.
  void set_input_result(double value);
  // The answer to the last StraightProbe (G38.2-G38.5): where the probe tripped (or lost
  // contact), latched by the servo thread, in machine coordinates and the machine's units, and
  // whether it did. #5061-#5069 take that position in the program's coordinates and units,
  // #5070 1 or 0, and a probe file opened with (PROBEOPEN name) gets a line. The caller stops
  // calling step() after a StraightProbe until the move is over, calls this, then
  // set_machine_position() with where the machine stopped. An error the machine raised (no
  // contact in G38.2/G38.4, tripped already at the start) is the caller's to report.
  // This call does not move the interpreter's position: until set_machine_position() says
  // where the machine stopped (before the next step()), the probe move counts as having
  // reached its programmed end. Without this call, the next step() reads on as LinuxCNC's
  // standalone rs274 does (what cncd-check and the goldens see): #5061-#5069 the programmed
  // end, #5070 0, and the position rs274's canon gives, the end backed off 0.254 mm (0.01 in)
  // toward where the move started. A probe file line that cannot be written makes the next
  // step() fail at the probe's line.
  void set_probe_result(const Pose& trip_machine, bool tripped);

  // Line number of the block last executed.
  int current_line() const;
  // The line of the open program's own file the interpreter stands at: current_line() there,
  // and inside a subroutine file the line of the call that entered it.
  int program_line() const;

  // The dialect in effect for the open program: InterpOptions::dialect, or the one its first
  // line names.
  Dialect dialect() const;
  // Block delete (InterpOptions::block_delete) from the next line read on: the panel's switch.
  void set_block_delete(bool on);

  InterpState state() const;
  // Coordinate system `system` (1..9 = G54..G59.3) from the parameters, machine units.
  Pose coord_system_origin(int system, double* rotation_deg = nullptr) const;
  // Sets the origin of coordinate system `system` (1..9) for the axes in the `axes` mask
  // (bit 0 = X), in machine units, and its XY rotation when given, as G10 L2 does. The
  // machine stays where it is; a program position in the active system moves with it. Call
  // between programs only. Refuses values that are not storable (stored_values.hpp): returns
  // why, and nothing changes.
  std::optional<std::string> set_coord_system_origin(int system, const Pose& origin,
                                                     std::uint32_t axes,
                                                     std::optional<double> rotation_deg);

  // The tool table as the interpreter holds it (offsets in the table's units), by number.
  std::vector<ToolEntry> tools() const;
  std::optional<ToolEntry> tool(int number) const;
  // Adds or replaces one entry, as G10 L1 does: the tool in the spindle takes a new length at
  // its next G43. Call between programs only. Refuses an entry that is not storable
  // (tool_entry_problem()): returns why, and nothing changes.
  std::optional<std::string> set_tool(const ToolEntry& entry);

  // The tool the machine has in its spindle, when it is not the one the interpreter last read
  // of (a run aborted before an M6 it had read ahead was carried out). A tool length offset
  // from the table (G43) is taken again for that tool; G43.1 and G49 stay. The machine
  // position stays where it is. Call between programs only.
  void set_tool_in_spindle(int tool);
  // Replaces the whole tool table (a copy tools() gave), e.g. to put back what its file holds
  // when it could not be written. Call between programs only.
  void set_tools(const std::vector<ToolEntry>& tools);

  // The persistent parameters (those save_parameters() writes), in number order: a copy of
  // what the parameter file holds for a caller that wants to know whether they changed.
  std::vector<double> persistent_parameters() const;
  // Puts back a copy persistent_parameters() gave (when the file could not be written): the
  // active coordinate system (#5220), its origin and rotation and the G92 offset follow them,
  // and the machine stays where it is. Call between programs only.
  void restore_persistent_parameters(const std::vector<double>& values);

  // Writes the persistent parameters (coordinate systems, G28/G30 points, G92 offsets) to
  // InterpOptions::parameter_file, as LinuxCNC does when its interpreter shuts down: temp file,
  // flush, rename. Does nothing without a parameter file. Never writes over a file that was
  // refused at construction (load_error()): that one may not be a parameter file at all.
  std::optional<InterpError> save_parameters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Convenience: runs a whole program into `sink`. Returns the first error, if any.
std::optional<InterpError> run_program(Interpreter& interp, CanonSink& sink);

}  // namespace cncd::interp
