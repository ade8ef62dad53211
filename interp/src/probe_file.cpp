#include "cncd/interp/probe_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>

namespace cncd::interp {
namespace {

namespace fs = std::filesystem;

fs::path normal(const fs::path& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  return ec ? fs::absolute(path, ec).lexically_normal() : canonical;
}

// The state file `st` (of the probe file) is, or "".
std::string state_file_hit(const ProbeFileTarget& target, const struct stat* st) {
  const fs::path wanted = normal(target.path());
  for (const auto& file : target.state_files) {
    if (file.empty()) continue;
    struct stat state {};
    const bool same_inode = st != nullptr && ::stat(file.c_str(), &state) == 0 &&
                            state.st_dev == st->st_dev && state.st_ino == st->st_ino;
    if (same_inode || normal(file) == wanted) return file.string();
  }
  return "";
}

std::string refusal(const ProbeFileTarget& target, const std::string& why) {
  return "Cannot open probe file " + target.path().string() + ": " + why;
}

std::string kind_problem(const struct stat& st) {
  if (S_ISREG(st.st_mode)) return "";
  if (S_ISDIR(st.st_mode)) return std::strerror(EISDIR);
  if (S_ISLNK(st.st_mode)) return "it is a symbolic link (a probe file must be a regular file)";
  if (S_ISFIFO(st.st_mode)) return "it is a FIFO (a probe file must be a regular file)";
  return "it is not a regular file";
}

std::string state_problem(const std::string& state_file) {
  return "it is the machine's state file " + state_file + " (choose another name)";
}

}  // namespace

std::string probe_name_problem(const std::string& name) {
  if (name.empty()) return "PROBEOPEN without a file name: (PROBEOPEN results.txt)";
  if (name.find('/') != std::string::npos || name == "." || name == "..") {
    return "Cannot open probe file " + name +
           ": give a file name without a directory; probe files go to the probe directory "
           "([CNCD] PROBE_DIR)";
  }
  if (name.size() > NAME_MAX) return "Cannot open probe file " + name + ": name too long";
  return "";
}

std::string probe_target_problem(const ProbeFileTarget& target) {
  struct stat st {};
  if (::lstat(target.dir.c_str(), &st) == 0) {
    // The directory itself may be a symlink the administrator set up: follow it.
    if (::stat(target.dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
      return refusal(target, "the probe directory " + target.dir.string() + " is not a directory");
    }
  }
  const fs::path path = target.path();
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) return refusal(target, std::strerror(errno));
    if (const auto hit = state_file_hit(target, nullptr); !hit.empty())
      return refusal(target, state_problem(hit));
    return "";
  }
  if (const auto kind = kind_problem(st); !kind.empty()) return refusal(target, kind);
  if (const auto hit = state_file_hit(target, &st); !hit.empty())
    return refusal(target, state_problem(hit));
  if (::access(path.c_str(), W_OK) != 0) return refusal(target, std::strerror(errno));
  return "";
}

int open_probe_file(const ProbeFileTarget& target, std::string& error) {
  if (const auto problem = probe_name_problem(target.name); !problem.empty()) {
    error = problem;
    return -1;
  }
  std::error_code ec;
  if (!fs::exists(target.dir, ec)) {
    fs::create_directories(target.dir.parent_path(), ec);
    if (::mkdir(target.dir.c_str(), 0750) != 0 && errno != EEXIST) {
      error = refusal(target,
                      "cannot create the probe directory: " + std::string(std::strerror(errno)));
      return -1;
    }
  }
  const fs::path path = target.path();
  // Not O_TRUNC: what is opened is looked at before anything in it is lost.
  const int fd = ::open(path.c_str(),
                        O_WRONLY | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | O_NOCTTY, 0640);
  if (fd < 0) {
    const int why = errno;
    struct stat st {};
    error = refusal(target, ::lstat(path.c_str(), &st) == 0 && !kind_problem(st).empty()
                                ? kind_problem(st)
                                : std::string(std::strerror(why)));
    return -1;
  }
  struct stat st {};
  std::string problem;
  if (::fstat(fd, &st) != 0) {
    problem = std::strerror(errno);
  } else if (problem = kind_problem(st); problem.empty()) {
    if (const auto hit = state_file_hit(target, &st); !hit.empty()) {
      problem = state_problem(hit);
    } else if (::ftruncate(fd, 0) != 0 || ::lseek(fd, 0, SEEK_SET) < 0) {
      problem = std::strerror(errno);
    }
  }
  if (!problem.empty()) {
    ::close(fd);
    error = refusal(target, problem);
    return -1;
  }
  return fd;
}

std::string write_probe_text(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? std::strerror(errno) : std::strerror(EIO);
    done += static_cast<std::size_t>(n);
  }
  return "";
}

SyncProbeWriter::~SyncProbeWriter() {
  close();
}

std::string SyncProbeWriter::open(const ProbeFileTarget& target, const std::string&) {
  close();
  std::string error;
  fd_ = open_probe_file(target, error);
  path_ = target.path().string();
  return error;
}

std::string SyncProbeWriter::write(const std::string& line, const std::string&) {
  if (fd_ < 0) return "";
  const std::string why = write_probe_text(fd_, line);
  return why.empty() ? "" : "Cannot write probe file " + path_ + ": " + why;
}

void SyncProbeWriter::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace cncd::interp
