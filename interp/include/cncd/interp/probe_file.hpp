// The probe results file of (PROBEOPEN name): where it may be, how it is opened, and who
// writes it. A program names a file, not a path: it lands in one directory (the machine's
// [CNCD] PROBE_DIR), is a regular file (never a FIFO, device or symlink, which could freeze or
// redirect the writer), and is never one of the machine's state files (parameter file, tool
// table, position file), whatever the directories say.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace cncd::interp {

struct ProbeFileTarget {
  std::filesystem::path dir;  // the probe directory; created (mode 0750) when missing
  std::string name;           // a plain file name (probe_name_problem() is empty)
  // Files it may never be, compared by path and, when they exist, by inode.
  std::vector<std::filesystem::path> state_files;
  std::filesystem::path path() const { return dir / name; }
};

// Why `name` cannot name a probe file, or "": a name with a directory in it (a '/', "." or
// ".."), an absolute path, or one longer than a file name may be.
std::string probe_name_problem(const std::string& name);

// Why the target cannot be written, or "", without creating, opening or emptying anything: a
// check run (cncd-check, program.open) leaves the last run's results alone. A missing file or
// directory is no problem (both are made at the first result).
std::string probe_target_problem(const ProbeFileTarget& target);

// Creates or empties the target and opens it for appending, never blocking (O_NONBLOCK: a FIFO
// without a reader fails at once) nor following a symlink (O_NOFOLLOW); the opened file must
// be a regular file that is no state file before it is emptied. Returns the descriptor, or -1
// with `error` set ("Cannot open probe file PATH: why").
int open_probe_file(const ProbeFileTarget& target, std::string& error);

// Writes all of `text` to `fd`: "" or why not.
std::string write_probe_text(int fd, const std::string& text);

// Where the interpreter's probe lines go. The interpreter calls it on its own thread; a writer
// may write at once (the default, SyncProbeWriter) or queue the work for another thread (the
// daemon's, so that its loop never waits on a disk). `where` is "FILE:LINE" of the comment or
// probe, for messages.
class ProbeFileWriter {
 public:
  virtual ~ProbeFileWriter() = default;
  // Starts a new file, emptied before its first line; "" or why it cannot be (a queued writer
  // may only know later, and report it its own way).
  virtual std::string open(const ProbeFileTarget& target, const std::string& where) = 0;
  // Appends one line (with its newline) to the file open(); "" or why not.
  virtual std::string write(const std::string& line, const std::string& where) = 0;
  // Closes the file, if any.
  virtual void close() = 0;
};

// Opens and writes on the calling thread.
class SyncProbeWriter final : public ProbeFileWriter {
 public:
  SyncProbeWriter() = default;
  ~SyncProbeWriter() override;
  SyncProbeWriter(const SyncProbeWriter&) = delete;
  SyncProbeWriter& operator=(const SyncProbeWriter&) = delete;
  std::string open(const ProbeFileTarget& target, const std::string& where) override;
  std::string write(const std::string& line, const std::string& where) override;
  void close() override;

 private:
  int fd_ = -1;
  std::string path_;
};

}  // namespace cncd::interp
