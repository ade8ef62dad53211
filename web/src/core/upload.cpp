// Uploads: written beside their destination without a name, given one only when complete.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <utility>

#include "cncd/web/program_dir.hpp"
#include "crypto.hpp"
#include "program_dir_internal.hpp"

namespace cncd::web {
namespace {

std::string hidden_name() {
  return std::string(kUploadPrefix) + crypto::hex(crypto::random_bytes(8));
}

}  // namespace

std::unique_ptr<Upload> ProgramDir::start_upload(FileStatus& status) const {
  status = {};
  if (!dir_fd_) {
    status = fail(FileError::io, open_error_);
    return nullptr;
  }
  // Programs are read by cncd, which may run as another user: readable as umask allows.
  constexpr mode_t kMode = 0644;
  if (use_tmpfile_) {
    UniqueFd fd(::openat(dir_fd_.get(), ".", O_TMPFILE | O_WRONLY | O_CLOEXEC, kMode));
    if (fd) return std::unique_ptr<Upload>(new Upload(*this, std::move(fd), ""));
    // EOPNOTSUPP and EISDIR (old kernels) mean no O_TMPFILE here: the hidden file will do.
  }
  for (int attempt = 0; attempt < 8; ++attempt) {
    std::string name = hidden_name();
    UniqueFd fd(::openat(dir_fd_.get(), name.c_str(),
                         O_CREAT | O_EXCL | O_WRONLY | O_NOFOLLOW | O_CLOEXEC, kMode));
    if (fd) return std::unique_ptr<Upload>(new Upload(*this, std::move(fd), std::move(name)));
    if (errno != EEXIST) break;
  }
  status = fail(FileError::io,
                path_.string() + ": cannot create a file for the upload: " + errno_text(errno));
  return nullptr;
}

Upload::Upload(const ProgramDir& dir, UniqueFd file, std::string temp_name)
    : dir_(dir), file_(std::move(file)), temp_name_(std::move(temp_name)) {}

Upload::~Upload() {
  discard();
}

void Upload::abort() {
  discard();
}

void Upload::discard() {
  if (done_) return;
  done_ = true;
  file_.reset();  // an O_TMPFILE file vanishes with its last descriptor
  if (!temp_name_.empty()) ::unlinkat(dir_.dir_fd_.get(), temp_name_.c_str(), 0);
  temp_name_.clear();
}

FileStatus Upload::write(std::string_view chunk) {
  if (done_) return fail(FileError::io, "the upload is over");
  if (static_cast<std::int64_t>(chunk.size()) > dir_.max_upload_bytes() - size_) {
    discard();
    return fail(FileError::too_large, "the upload is larger than " +
                                          std::to_string(dir_.max_upload_bytes()) +
                                          " bytes ([WEB] MAX_UPLOAD_MB)");
  }
  while (!chunk.empty()) {
    const ssize_t n = ::write(file_.get(), chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      discard();
      return fail(FileError::io, "cannot write the upload: " + errno_text(error));
    }
    chunk.remove_prefix(static_cast<std::size_t>(n));
    size_ += n;
  }
  return {};
}

FileStatus Upload::commit(std::string_view name, const std::filesystem::path& running) {
  if (done_) return fail(FileError::io, "the upload is over");
  FileStatus status = bad_name(name);
  if (status.ok()) status = dir_.refuse_running(name, running);
  if (status.ok() && ::fsync(file_.get()) != 0) {
    status = fail(FileError::io, "cannot write the upload: " + errno_text(errno));
  }
  const int dir = dir_.dir_fd_.get();
  if (status.ok() && temp_name_.empty()) {
    // An anonymous file gets a hidden name first: linkat cannot replace an existing program,
    // renameat can, atomically.
    std::string hidden = hidden_name();
    const std::string proc = "/proc/self/fd/" + std::to_string(file_.get());
    if (::linkat(AT_FDCWD, proc.c_str(), dir, hidden.c_str(), AT_SYMLINK_FOLLOW) == 0 ||
        ::linkat(file_.get(), "", dir, hidden.c_str(), AT_EMPTY_PATH) == 0) {
      temp_name_ = std::move(hidden);
    } else {
      status = fail(FileError::io, "cannot name the upload: " + errno_text(errno));
    }
  }
  if (status.ok()) {
    const std::string target(name);
    if (::renameat(dir, temp_name_.c_str(), dir, target.c_str()) == 0) {
      temp_name_.clear();
      if (const int fd = ::openat(dir, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC); fd >= 0) {
        ::fsync(fd);  // the new name reaches the disk
        ::close(fd);
      }
    } else {
      status = fail(FileError::io,
                    "cannot put the upload in place as '" + target + "': " + errno_text(errno));
    }
  }
  discard();
  return status;
}

}  // namespace cncd::web
