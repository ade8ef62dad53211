#include "cncd/drivers/exclusive_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace cncd::drivers {
namespace {

// The pid the holder wrote, or 0 (not written yet, or a lock file we could only read).
pid_t pid_in(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  if (n <= 0) return 0;
  char* end = nullptr;
  const long pid = std::strtol(text, &end, 10);
  return pid > 0 && end != text ? static_cast<pid_t>(pid) : 0;
}

// The holder of a flock on the file behind `fd`, as the kernel lists it in /proc/locks
// ("1: FLOCK  ADVISORY  WRITE 1234 08:01:5678 0 EOF"), or 0.
pid_t pid_in_proc_locks(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return 0;
  char id[64];
  std::snprintf(id, sizeof id, "%02x:%02x:%lu", major(st.st_dev), minor(st.st_dev),
                static_cast<unsigned long>(st.st_ino));
  std::ifstream locks("/proc/locks");
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream fields(line);
    std::string number, kind, mode, access, device;
    long pid = 0;
    if (fields >> number >> kind >> mode >> access >> pid >> device && kind == "FLOCK" &&
        device == id && pid > 0) {
      return static_cast<pid_t>(pid);
    }
  }
  return 0;
}

}  // namespace

ExclusiveLock::~ExclusiveLock() {
  if (fd_ >= 0) ::close(fd_);
}

ExclusiveLock::ExclusiveLock(ExclusiveLock&& other) noexcept
    : fd_(other.fd_), holder_(other.holder_) {
  other.fd_ = -1;
}

ExclusiveLock& ExclusiveLock::operator=(ExclusiveLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    holder_ = other.holder_;
    other.fd_ = -1;
  }
  return *this;
}

ExclusiveLock::Outcome ExclusiveLock::take(const std::filesystem::path& file, std::string& error) {
  const auto os_error = [&](const char* what) {
    error = std::string(what) + " '" + file.string() + "': " + std::strerror(errno);
    return Outcome::failed;
  };
  // Locked through a read-only descriptor, so that a daemon holding the lock does not keep
  // the file system from being remounted read-only. O_NONBLOCK: a FIFO planted in the lock's
  // place must not hang the start.
  constexpr int kFlags = O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK;
  int fd = ::open(file.c_str(), kFlags | O_CREAT, 0644);
  if (fd < 0 && (errno == EACCES || errno == EPERM)) {
    // Another user's lock file in a shared sticky directory (/run/lock, protected_regular).
    fd = ::open(file.c_str(), kFlags);
  }
  if (fd < 0) return os_error("cannot open the lock file");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    error = "the lock file '" + file.string() + "' is not a regular file";
    return Outcome::failed;
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK) {
      const Outcome outcome = os_error("cannot lock");
      ::close(fd);
      return outcome;
    }
    holder_ = pid_in(fd);
    if (holder_ == 0) holder_ = pid_in_proc_locks(fd);
    ::close(fd);
    return Outcome::busy;
  }
  // The pid for whoever is refused next. A lock file we may not write (another user's), or
  // a full disk, leaves it out: the lock holds all the same, its holder then found in
  // /proc/locks.
  const int out = ::open(file.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (out >= 0) {
    char text[32];
    const int n = std::snprintf(text, sizeof text, "%ld\n", static_cast<long>(::getpid()));
    if (::ftruncate(out, 0) == 0) {
      [[maybe_unused]] const ssize_t written = ::pwrite(out, text, static_cast<std::size_t>(n), 0);
    }
    ::close(out);
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  holder_ = ::getpid();
  return Outcome::taken;
}

}  // namespace cncd::drivers
