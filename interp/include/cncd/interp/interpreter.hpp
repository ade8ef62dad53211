// The RS274NGC interpreter. Single-threaded: one thread owns an Interpreter. Reads the program
// incrementally (memory does not grow with program length) and emits canonical commands to a
// CanonSink block by block.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cncd/interp/canon.hpp"
#include "cncd/interp/to_machine.hpp"  // MachineTracker, which every user of the stream needs

namespace cncd::interp {

struct InterpError {
  std::string file;
  int line = 0;    // 1-based, 0 = not tied to a line
  int column = 0;  // 1-based, 0 = unknown
  std::string message;
  // "FILE:LINE:COLUMN: message" (column left out when 0)
  std::string to_string() const;
};

struct InterpOptions {
  Units machine_units = Units::mm;       // units of the machine (INI LINEAR_UNITS)
  std::filesystem::path parameter_file;  // empty = none
  std::filesystem::path tool_table;      // empty = none
  // Units the tool table is written in (LinuxCNC: the machine's units; its standalone rs274
  // reads tables as inches). Unset = machine_units.
  std::optional<Units> tool_table_units;
  std::vector<std::filesystem::path> subroutine_path;
  std::string startup_code;   // RS274NGC_STARTUP_CODE, run before the program
  bool block_delete = false;  // skip lines starting with '/'
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

  // Opens a program file and resets to the start-of-program modal state.
  std::optional<InterpError> open(const std::filesystem::path& program);
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
  // Line number of the block last executed.
  int current_line() const;

  // Writes the persistent parameters (coordinate systems, G28/G30 points, G92 offsets) to
  // InterpOptions::parameter_file, as LinuxCNC does when its interpreter shuts down: temp file,
  // flush, rename. Does nothing without a parameter file.
  std::optional<InterpError> save_parameters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Convenience: runs a whole program into `sink`. Returns the first error, if any.
std::optional<InterpError> run_program(Interpreter& interp, CanonSink& sink);

}  // namespace cncd::interp
