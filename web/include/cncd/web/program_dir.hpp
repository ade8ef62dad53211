// The program directory as the web sees it ([WEB] PROGRAM_DIR): names checked, uploads
// written atomically, nothing reachable outside it. Every operation goes through one
// O_PATH descriptor of the directory opened at construction (openat, renameat, linkat,
// unlinkat), so replacing the directory's path by a symlink later cannot redirect a write.
#pragma once

#include <sys/stat.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cncd::web {

// "" when `name` is one plain path component a program may be called, else why not: empty,
// "." or "..", containing '/', NUL or a control character (below 0x20, or 0x7f), starting
// with '.' (hidden files, and the names uploads use while they are written), or over 255
// bytes. Any extension, any other byte (UTF-8) is fine.
std::string check_program_name(std::string_view name);

// URL percent-decoding of one path segment ('+' stays '+'). Refused: a '%' not followed by
// two hex digits, and %00.
struct Decoded {
  std::string text;
  std::string error;  // "" when decoded
  bool ok() const { return error.empty(); }
};
Decoded percent_decode(std::string_view segment);

// An owned file descriptor.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd() { reset(); }
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset(int fd = -1);
  explicit operator bool() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// What went wrong, for the HTTP status: bad_name 400, not_found 404, exists 409,
// running 409, too_large 413, not_regular 403, outside 403, io 500.
enum class FileError {
  none,
  bad_name,
  not_found,
  exists,
  running,
  too_large,
  not_regular,
  outside,
  io
};

struct FileStatus {
  FileError error = FileError::none;
  std::string message;  // for the client; names the file and says what is wrong
  bool ok() const { return error == FileError::none; }
};

struct ProgramEntry {
  std::string name;
  std::int64_t size = 0;
  std::chrono::system_clock::time_point mtime;
  std::optional<double> estimate_s;  // not filled here: the server's estimate, when it has one
};

class ProgramDir;

// One upload in progress: an anonymous file in the program directory (O_TMPFILE; where the
// filesystem has none, a hidden ".cncd-upload-*" file that list() skips), which becomes a
// program only by commit(). Destroyed or aborted without commit, it leaves nothing behind.
// It must not outlive the ProgramDir that started it.
class Upload {
 public:
  ~Upload();
  Upload(const Upload&) = delete;
  Upload& operator=(const Upload&) = delete;

  // Appends a chunk. Past the size limit: too_large, and the upload is aborted.
  FileStatus write(std::string_view chunk);
  std::int64_t size() const { return size_; }
  // fsync, then puts the file in place as `name` atomically (replacing a program of that name
  // that is not `running`). Refused: a bad name, `name` being the program `running` names
  // (the open and running program, an absolute path; empty: none), an aborted upload.
  // The upload is over afterwards whatever the outcome.
  FileStatus commit(std::string_view name, const std::filesystem::path& running = {});
  // Drops the data; nothing remains in the directory.
  void abort();

 private:
  friend class ProgramDir;
  Upload(const ProgramDir& dir, UniqueFd file, std::string temp_name);
  void discard();

  const ProgramDir& dir_;
  UniqueFd file_;
  std::string temp_name_;  // the hidden name of the fallback, "" for an O_TMPFILE file
  std::int64_t size_ = 0;
  bool done_ = false;
};

// An open, regular program file for download.
struct ReadableFile {
  UniqueFd fd;
  std::int64_t size = 0;
  std::chrono::system_clock::time_point mtime;
};

class ProgramDir {
 public:
  // Opens `dir` (which should be absolute and a directory); ok() says whether it could.
  // Removes what uploads cut short by a crash left (remove_stale_uploads, an hour old).
  ProgramDir(std::filesystem::path dir, std::int64_t max_upload_bytes);

  // "" when the directory is open, else why not (the server refuses to start).
  const std::string& open_error() const { return open_error_; }
  bool ok() const { return open_error_.empty(); }
  const std::filesystem::path& path() const { return path_; }
  std::int64_t max_upload_bytes() const { return max_upload_bytes_; }

  // The programs: regular files (not symlinks, not hidden), sorted by name. nullopt and
  // `status` set when the directory cannot be read.
  std::optional<std::vector<ProgramEntry>> list(FileStatus& status) const;

  // Starts an upload; nullptr and `status` set when no temporary file can be made.
  std::unique_ptr<Upload> start_upload(FileStatus& status) const;

  // Renames a program; refused when either name is bad, `from` is missing or not a regular
  // file, `to` exists (exists), or either is the `running` program.
  FileStatus rename(std::string_view from, std::string_view to,
                    const std::filesystem::path& running = {}) const;
  // Deletes a program (a regular file or a symlink, never a directory); refused for the
  // `running` program.
  FileStatus remove(std::string_view name, const std::filesystem::path& running = {}) const;

  // Opens a program for reading: O_NOFOLLOW (a symlink is refused), a regular file only (a
  // FIFO or device is refused without blocking).
  std::optional<ReadableFile> open_for_read(std::string_view name, FileStatus& status) const;

  // The absolute path program.open should get for `name`: the directory's real path joined
  // with the name's real path, which must stay inside the directory (a symlink inside that
  // points outside is refused: outside) and be a regular file.
  std::optional<std::filesystem::path> resolve(std::string_view name, FileStatus& status) const;

  // Removes the hidden files of uploads (".cncd-upload-*") not written to for `age`: what a
  // crash between writing and renaming leaves. Returns how many.
  int remove_stale_uploads(std::chrono::seconds age) const;

  // True when `name` in this directory is the `running` program: the same path, or the same
  // file (device and inode) reached another way.
  bool is_running(std::string_view name, const std::filesystem::path& running) const;

  // For tests: make uploads use the hidden-file fallback instead of O_TMPFILE.
  void set_use_tmpfile(bool use) { use_tmpfile_ = use; }

 private:
  friend class Upload;
  // lstat of `name` in the directory: not_found, io, or ok.
  FileStatus lstat_entry(std::string_view name, struct stat& st) const;
  // `running` when `name` is the running program, else ok.
  FileStatus refuse_running(std::string_view name, const std::filesystem::path& running) const;

  std::filesystem::path path_;
  std::int64_t max_upload_bytes_;
  UniqueFd dir_fd_;
  std::string open_error_;
  bool use_tmpfile_ = true;
};

}  // namespace cncd::web
