// What the task's commands end in, as the task knows it: a refusal or failure of a kind, with
// its message, or for the commands answered later (machine.on, program.open, program.abort,
// mdi.execute) an outcome posted under the request's token. The control protocol's error codes
// and JSON are the server's business (rpc.cpp, docs/protocol.md).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>

namespace cncd::daemon {

enum class TaskErrorKind {
  wrong_state,  // not allowed in the machine's current state
  not_homed,    // motion needs homed joints
  program,      // the program could not be opened or run, or the interpreter stopped it
  busy,         // something else is running
  bad_value,    // a value the machine or the interpreter refuses
  save_failed,  // a file (tool table, parameter file) could not be written
  fault,        // the machine did not do it: a drive, its feedback or the estop input
  cancelled,    // cancelled before it finished
  unavailable,  // a record the daemon keeps (the job history) cannot be opened or read
};

// Thrown by a command the task refuses or cannot carry out; nothing has changed then, unless
// the command says otherwise.
class TaskError : public std::runtime_error {
 public:
  TaskError(TaskErrorKind kind, const std::string& message)
      : std::runtime_error(message), kind_(kind) {}
  TaskErrorKind kind() const { return kind_; }

 private:
  TaskErrorKind kind_;
};

// The command has been carried out.
struct CommandDone {};
// program.open: the program is open; `path` is its file, symlinks resolved.
struct ProgramOpened {
  std::string path;
};
// program.preview, jobs.history, jobs.stats: the result, already serialized (a preview is
// large, and shared by every client that asks for the same one).
struct RawResult {
  std::shared_ptr<const std::string> json;
};
using TaskOutcome = std::variant<CommandDone, ProgramOpened, RawResult, TaskError>;

// Where the task posts the outcomes of the commands answered later, each under the token the
// command was given.
class TaskAnswers {
 public:
  virtual ~TaskAnswers() = default;
  virtual void post(std::uint64_t token, TaskOutcome outcome) = 0;
};

}  // namespace cncd::daemon
