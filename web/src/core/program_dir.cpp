#include "cncd/web/program_dir.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "program_dir_internal.hpp"

namespace cncd::web {

std::string errno_text(int error) {
  return std::strerror(error);
}

std::chrono::system_clock::time_point to_time_point(const struct timespec& ts) {
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec)));
}

FileStatus fail(FileError error, std::string message) {
  return {error, std::move(message)};
}

FileStatus bad_name(std::string_view name) {
  const std::string why = check_program_name(name);
  if (why.empty()) return {};
  return fail(FileError::bad_name, why);
}

ProgramDir::ProgramDir(std::filesystem::path dir, std::int64_t max_upload_bytes)
    : path_(std::move(dir)), max_upload_bytes_(max_upload_bytes) {
  dir_fd_.reset(::open(path_.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC));
  if (!dir_fd_) {
    open_error_ = path_.string() + ": cannot open the program directory: " + errno_text(errno);
    return;
  }
  remove_stale_uploads(std::chrono::hours(1));
}

int ProgramDir::remove_stale_uploads(std::chrono::seconds age) const {
  const int fd = dir_fd_ ? ::openat(dir_fd_.get(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC) : -1;
  DIR* dir = fd >= 0 ? ::fdopendir(fd) : nullptr;
  if (dir == nullptr) {
    if (fd >= 0) ::close(fd);
    return 0;
  }
  const auto now = std::chrono::system_clock::now();
  int removed = 0;
  while (const dirent* e = ::readdir(dir)) {
    if (!std::string_view(e->d_name).starts_with(kUploadPrefix)) continue;
    struct stat st {};
    if (::fstatat(::dirfd(dir), e->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(st.st_mode) &&
        to_time_point(st.st_mtim) + age <= now && ::unlinkat(::dirfd(dir), e->d_name, 0) == 0) {
      ++removed;
    }
  }
  ::closedir(dir);
  return removed;
}

FileStatus ProgramDir::lstat_entry(std::string_view name, struct stat& st) const {
  if (!dir_fd_) return fail(FileError::io, open_error_);
  const std::string n(name);
  if (::fstatat(dir_fd_.get(), n.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) return {};
  if (errno == ENOENT) return fail(FileError::not_found, "no program '" + n + "'");
  return fail(FileError::io, "'" + n + "': " + errno_text(errno));
}

bool ProgramDir::is_running(std::string_view name, const std::filesystem::path& running) const {
  if (running.empty()) return false;
  if ((path_ / std::string(name)).lexically_normal() == running.lexically_normal()) return true;
  struct stat entry {};
  struct stat program {};
  if (!dir_fd_ ||
      ::fstatat(dir_fd_.get(), std::string(name).c_str(), &entry, AT_SYMLINK_NOFOLLOW) != 0 ||
      ::stat(running.c_str(), &program) != 0) {
    return false;
  }
  return entry.st_dev == program.st_dev && entry.st_ino == program.st_ino;
}

FileStatus ProgramDir::refuse_running(std::string_view name,
                                      const std::filesystem::path& running) const {
  if (!is_running(name, running)) return {};
  return fail(FileError::running,
              "'" + std::string(name) + "' is the program that is open and running");
}

std::optional<std::vector<ProgramEntry>> ProgramDir::list(FileStatus& status) const {
  status = {};
  if (!dir_fd_) {
    status = fail(FileError::io, open_error_);
    return std::nullopt;
  }
  const int fd = ::openat(dir_fd_.get(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  DIR* dir = fd >= 0 ? ::fdopendir(fd) : nullptr;
  if (dir == nullptr) {
    status = fail(FileError::io, path_.string() + ": cannot list: " + errno_text(errno));
    if (fd >= 0) ::close(fd);
    return std::nullopt;
  }
  std::vector<ProgramEntry> out;
  while (const dirent* e = ::readdir(dir)) {
    const std::string_view name = e->d_name;
    if (name.empty() || name.front() == '.') continue;  // hidden, and uploads in progress
    struct stat st {};
    if (::fstatat(::dirfd(dir), e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0) continue;
    if (!S_ISREG(st.st_mode)) continue;
    out.push_back({std::string(name), st.st_size, to_time_point(st.st_mtim), std::nullopt});
  }
  ::closedir(dir);
  std::sort(out.begin(), out.end(),
            [](const ProgramEntry& a, const ProgramEntry& b) { return a.name < b.name; });
  return out;
}

FileStatus ProgramDir::rename(std::string_view from, std::string_view to,
                              const std::filesystem::path& running) const {
  for (const auto name : {from, to}) {
    if (auto s = bad_name(name); !s.ok()) return s;
    if (auto s = refuse_running(name, running); !s.ok()) return s;
  }
  struct stat st {};
  if (auto s = lstat_entry(from, st); !s.ok()) return s;
  if (!S_ISREG(st.st_mode)) {
    return fail(FileError::not_regular, "'" + std::string(from) + "' is not a regular file");
  }
  const std::string f(from);
  const std::string t(to);
  int rc = ::renameat2(dir_fd_.get(), f.c_str(), dir_fd_.get(), t.c_str(), RENAME_NOREPLACE);
  if (rc != 0 && errno == EINVAL) {
    // A filesystem without RENAME_NOREPLACE: a hard link cannot replace either.
    rc = ::linkat(dir_fd_.get(), f.c_str(), dir_fd_.get(), t.c_str(), 0);
    if (rc == 0) ::unlinkat(dir_fd_.get(), f.c_str(), 0);
  }
  if (rc == 0) return {};
  if (errno == EEXIST) return fail(FileError::exists, "'" + t + "' exists already");
  if (errno == ENOENT) return fail(FileError::not_found, "no program '" + f + "'");
  return fail(FileError::io, "cannot rename '" + f + "' to '" + t + "': " + errno_text(errno));
}

FileStatus ProgramDir::remove(std::string_view name, const std::filesystem::path& running) const {
  if (auto s = bad_name(name); !s.ok()) return s;
  if (auto s = refuse_running(name, running); !s.ok()) return s;
  struct stat st {};
  if (auto s = lstat_entry(name, st); !s.ok()) return s;
  if (!S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode)) {
    return fail(FileError::not_regular, "'" + std::string(name) + "' is not a regular file");
  }
  if (::unlinkat(dir_fd_.get(), std::string(name).c_str(), 0) == 0) return {};
  if (errno == ENOENT) return fail(FileError::not_found, "no program '" + std::string(name) + "'");
  return fail(FileError::io, "cannot delete '" + std::string(name) + "': " + errno_text(errno));
}

std::optional<ReadableFile> ProgramDir::open_for_read(std::string_view name,
                                                      FileStatus& status) const {
  status = bad_name(name);
  if (!status.ok()) return std::nullopt;
  // Look before opening: opening a FIFO or a device can block or have effects.
  struct stat st {};
  status = lstat_entry(name, st);
  if (!status.ok()) return std::nullopt;
  const auto not_regular = [&] {
    status = fail(FileError::not_regular, "'" + std::string(name) + "' is not a regular file");
    return std::nullopt;
  };
  if (!S_ISREG(st.st_mode)) return not_regular();
  ReadableFile file;
  file.fd.reset(::openat(dir_fd_.get(), std::string(name).c_str(),
                         O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC));
  if (!file.fd) {
    if (errno == ELOOP) return not_regular();
    status = fail(errno == ENOENT ? FileError::not_found : FileError::io,
                  "cannot open '" + std::string(name) + "': " + errno_text(errno));
    return std::nullopt;
  }
  // It may have been swapped between the look and the open.
  if (::fstat(file.fd.get(), &st) != 0 || !S_ISREG(st.st_mode)) return not_regular();
  ::fcntl(file.fd.get(), F_SETFL, 0);
  file.size = st.st_size;
  file.mtime = to_time_point(st.st_mtim);
  return file;
}

std::optional<std::filesystem::path> ProgramDir::resolve(std::string_view name,
                                                         FileStatus& status) const {
  status = bad_name(name);
  if (!status.ok()) return std::nullopt;
  std::error_code ec;
  // The directory the descriptor holds, even if its path was swapped since.
  auto base = std::filesystem::canonical("/proc/self/fd/" + std::to_string(dir_fd_.get()), ec);
  if (ec) base = std::filesystem::canonical(path_, ec);
  if (ec) {
    status = fail(FileError::io, path_.string() + ": " + ec.message());
    return std::nullopt;
  }
  const auto full = std::filesystem::canonical(base / std::string(name), ec);
  if (ec) {
    status = fail(ec == std::errc::no_such_file_or_directory ? FileError::not_found : FileError::io,
                  "'" + std::string(name) + "': " + ec.message());
    return std::nullopt;
  }
  const std::string prefix = base.string() + "/";
  if (!full.string().starts_with(prefix)) {
    status =
        fail(FileError::outside, "'" + std::string(name) + "' leads outside the program directory");
    return std::nullopt;
  }
  if (!std::filesystem::is_regular_file(full, ec)) {
    status = fail(FileError::not_regular, "'" + std::string(name) + "' is not a regular file");
    return std::nullopt;
  }
  return full;
}

}  // namespace cncd::web
