// Test helpers: a real cncd process on a temporary socket, and running commands.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace cncd::test {

// A fresh temporary directory, removed on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path write(const std::string& name, const std::string& content) const;

 private:
  std::filesystem::path path_;
};

// The whole content of a file; "" when it cannot be read.
std::string slurp(const std::filesystem::path& path);

// Copies config/examples/<name>.* (INI, parameter and tool files) into `dir`, so that a
// daemon under test writes its state there and not into the source tree. Returns the INI,
// made to run from there as relocate_example_ini() does.
std::filesystem::path copy_example_machine(const std::filesystem::path& dir,
                                           const std::string& name = "sim_mm");

// The text of an example INI made to run from another directory: its program directory
// ([DISPLAY] PROGRAM_PREFIX, relative to config/examples) is the source tree's examples/
// again, and the directory the copy is written to is a program directory too ([CNCD]
// PROGRAM_DIRS = .), for the programs tests write beside it.
std::string relocate_example_ini(std::string text);

struct CommandResult {
  int exit_status = -1;  // exit code, or 128 + signal
  std::string out;
  std::string err;
};

// Runs argv to completion (stdin from /dev/null), capturing stdout and stderr.
CommandResult run_command(const std::vector<std::string>& argv);

// A command left running, its standard input a pipe the test writes to.
class BackgroundCommand {
 public:
  explicit BackgroundCommand(const std::vector<std::string>& argv);
  ~BackgroundCommand();
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;
  bool write_stdin(const std::string& text);
  // What it has written to stderr so far.
  std::string err_so_far() const;
  // Closes its standard input and waits for it to end.
  CommandResult wait();
  pid_t pid() const { return pid_; }

 private:
  TempDir dir_;
  pid_t pid_ = -1;
  int stdin_fd_ = -1;
};

class DaemonProcess {
 public:
  DaemonProcess() = default;
  ~DaemonProcess();
  DaemonProcess(const DaemonProcess&) = delete;
  DaemonProcess& operator=(const DaemonProcess&) = delete;

  // Starts cncd with `args` plus --socket, and --state-dir `dir` unless `args` name one or
  // use_default_state_dir() was called; waits until the socket accepts connections.
  // Returns "" or what went wrong (with cncd's log).
  std::string start(const std::filesystem::path& dir, const std::vector<std::string>& args);
  // SIGTERM and wait; returns the exit status.
  int stop();
  // SIGTERM and wait up to `limit`: the exit status, or -2 when it had not ended by then (it
  // is then killed with SIGKILL).
  int stop_within(int limit_ms);
  // Sends `signal` without waiting (SIGTERM: the daemon starts shutting down).
  void signal(int signal);
  // SIGKILL and wait: the daemon dies wherever it is. Returns the exit status.
  int kill_hard();
  // The next start() leaves the state directory to the INI and the environment.
  void use_default_state_dir() { default_state_dir_ = true; }
  const std::string& socket() const { return socket_; }
  // The running daemon's pid, or -1.
  pid_t pid() const { return pid_; }
  std::string log() const;

 private:
  // Sends `signal` and waits; the exit status.
  int end_with(int signal);

  pid_t pid_ = -1;
  bool default_state_dir_ = false;
  std::string socket_;
  std::filesystem::path log_;
};

}  // namespace cncd::test
