#include "evdev_reader.hpp"

#include <fcntl.h>
#include <linux/input.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <utility>

#include "monotonic_clock.hpp"

namespace cncd::drivers {
namespace {

// A lost or absent device is tried again this often: soon enough that a replugged pendant
// works again at once to a person, rarely enough to cost nothing while it stays away.
constexpr std::int64_t kReopenDelayNs = 250'000'000;
constexpr std::size_t kBufferEvents = 64;
constexpr std::uint16_t kContourDesign = 0x0b33;  // USB vendor of the Shuttle jog wheels

std::string error_text(int error) {
  return std::strerror(error);
}

}  // namespace

void EvdevNotices::add(DriverNotice::Level level, std::string text) {
  const std::lock_guard lock(mutex_);
  if (queue_.size() >= kMax) {
    queue_.pop_front();
    ++dropped_;
  }
  queue_.push_back(DriverNotice{level, std::move(text)});
}

bool EvdevNotices::take(DriverNotice& out) {
  const std::lock_guard lock(mutex_);
  if (dropped_ > 0) {
    out = DriverNotice{DriverNotice::Level::warning,
                       std::to_string(dropped_) + " notices of input devices were dropped"};
    dropped_ = 0;
    return true;
  }
  if (queue_.empty()) return false;
  out = std::move(queue_.front());
  queue_.pop_front();
  return true;
}

EvdevReader::EvdevReader(std::string path, std::vector<EvdevBinding> bindings, std::int64_t hold_ns,
                         EvdevNotices& notices)
    : path_(std::move(path)),
      bindings_(std::move(bindings)),
      hold_ns_(hold_ns),
      notices_(notices),
      buffer_(kBufferEvents * sizeof(input_event)) {
  for (const EvdevBinding& b : bindings_) {
    switch (b.target) {
      case EvdevBinding::Target::input:
        input_mask_ |= std::uint64_t{1} << b.index;
        break;
      case EvdevBinding::Target::counter:
        counter_mask_ |= 1u << b.index;
        break;
      case EvdevBinding::Target::analog:
        analog_mask_ |= 1u << b.index;
        break;
    }
  }
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) wake_error_ = errno;
}

EvdevReader::~EvdevReader() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void EvdevReader::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

void EvdevReader::stop() {
  if (!thread_.joinable()) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(wake_fd_, &one, sizeof one);
  thread_.join();
  std::uint64_t count = 0;
  [[maybe_unused]] const ssize_t read = ::read(wake_fd_, &count, sizeof count);
}

void EvdevReader::publish(PanelFeedback& out) const noexcept {
  out.inputs = (out.inputs & ~input_mask_) | shown_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < counts_.size(); ++i) {
    if ((counter_mask_ & (1u << i)) == 0) continue;
    out.counts[i] = counts_[i].load(std::memory_order_acquire);
    out.counter_bits[i] = 32;
  }
  for (std::size_t i = 0; i < analog_.size(); ++i) {
    if ((analog_mask_ & (1u << i)) != 0) out.analog[i] = analog_[i].load(std::memory_order_acquire);
  }
}

void EvdevReader::run() {
  if (wake_fd_ < 0) {
    notices_.add(DriverNotice::Level::warning,
                 "input device " + path_ + ": not read (eventfd: " + error_text(wake_error_) + ")");
    return;
  }
  for (;;) {
    const std::int64_t now = monotonic_ns();
    if (fd_ < 0 && now >= next_open_ && !open_device(now)) next_open_ = now + kReopenDelayNs;
    std::int64_t due = settle(now);
    if (fd_ < 0) due = std::min(due, next_open_);
    int timeout_ms = -1;
    if (due != INT64_MAX)
      timeout_ms =
          static_cast<int>(std::clamp<std::int64_t>((due - now + 999'999) / 1'000'000, 0, 1000));
    pollfd fds[2] = {{wake_fd_, POLLIN, 0}, {fd_, POLLIN, 0}};
    if (::poll(fds, fd_ >= 0 ? 2 : 1, timeout_ms) < 0) continue;  // EINTR: look again
    if (fds[0].revents != 0) break;
    if (fd_ >= 0 && fds[1].revents != 0) drain(monotonic_ns());
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  have_ = 0;
  held_ = 0;
  shown_bits_ = 0;
  shown_.store(0, std::memory_order_release);
}

bool EvdevReader::open_device(std::int64_t now) {
  const int fd = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (!absent_reported_) {
      notices_.add(DriverNotice::Level::warning, "input device " + path_ + ": cannot be opened (" +
                                                     error_text(errno) +
                                                     "); its buttons read released until it can");
      absent_reported_ = true;
    }
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || (!S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode))) {
    ::close(fd);
    if (!absent_reported_) {
      notices_.add(DriverNotice::Level::warning,
                   "input device " + path_ + ": is neither an input event device nor a FIFO");
      absent_reported_ = true;
    }
    return false;
  }
  fd_ = fd;
  fifo_ = S_ISFIFO(st.st_mode);
  absent_reported_ = false;
  have_ = 0;
  dropping_ = false;
  dial_positions_ = false;
  dial_last_.fill(-1);
  std::string what = "a FIFO";
  if (!fifo_) {
    std::array<char, 256> name{};
    what = ::ioctl(fd_, EVIOCGNAME(name.size() - 1), name.data()) >= 0 ? name.data() : "";
    input_id id{};
    dial_positions_ = ::ioctl(fd_, EVIOCGID, &id) == 0 && id.vendor == kContourDesign;
    // A pendant's keys are the machine's: they must not type into a console or a desktop too.
    if (::ioctl(fd_, EVIOCGRAB, 1) != 0) {
      notices_.add(DriverNotice::Level::warning, "input device " + path_ + ": cannot be grabbed (" +
                                                     error_text(errno) +
                                                     "): another program may take its events");
    }
    sync_state(now);
  }
  notices_.add(DriverNotice::Level::info, "input device " + path_ + ": reading (" + what + ")");
  return true;
}

// A device opened (or resynchronized after the kernel dropped events) tells its keys held and
// its axes' positions now: events only say what changes.
void EvdevReader::sync_state(std::int64_t now) {
  std::array<unsigned long,
             (KEY_CNT + CHAR_BIT * sizeof(unsigned long) - 1) / (CHAR_BIT * sizeof(unsigned long))>
      keys{};
  const bool have_keys = ::ioctl(fd_, EVIOCGKEY(sizeof keys), keys.data()) >= 0;
  constexpr std::size_t kWordBits = CHAR_BIT * sizeof(unsigned long);
  for (const EvdevBinding& b : bindings_) {
    if (b.target == EvdevBinding::Target::input && have_keys) {
      const bool down = (keys[b.code / kWordBits] >> (b.code % kWordBits) & 1u) != 0;
      const std::uint64_t bit = std::uint64_t{1} << b.index;
      if (down) {
        press(bit, now);
      } else {
        held_ &= ~bit;
      }
    } else if (b.target == EvdevBinding::Target::analog) {
      input_absinfo info{};
      if (::ioctl(fd_, EVIOCGABS(b.code), &info) == 0)
        analog_[static_cast<std::size_t>(b.index)].store(info.value, std::memory_order_release);
    }
  }
}

void EvdevReader::drain(std::int64_t now) {
  // Bounded, so that a device that never stops talking cannot keep stop() waiting.
  for (std::size_t round = 0; round < kBufferEvents && fd_ >= 0; ++round) {
    const ssize_t n = ::read(fd_, buffer_.data() + have_, buffer_.size() - have_);
    if (n > 0) {
      have_ += static_cast<std::size_t>(n);
      std::size_t used = 0;
      for (; have_ - used >= sizeof(input_event); used += sizeof(input_event)) {
        input_event event{};
        std::memcpy(&event, buffer_.data() + used, sizeof event);
        apply(event, now);
      }
      // A FIFO may deliver part of a record: keep it for the next read.
      std::memmove(buffer_.data(), buffer_.data() + used, have_ - used);
      have_ -= used;
      continue;
    }
    if (n == 0) {
      lose(fifo_ ? "its writer closed it" : "end of file", now);
      return;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return;
    lose(error_text(errno), now);
    return;
  }
}

void EvdevReader::lose(const std::string& why, std::int64_t now) {
  ::close(fd_);
  fd_ = -1;
  std::string text = "input device " + path_ + ": lost (" + why + ")";
  if (have_ > 0) text += ", " + std::to_string(have_) + " bytes of an incomplete event dropped";
  text += "; its buttons read released until it is back";
  have_ = 0;
  dropping_ = false;
  // Released, but each press still shows for its hold time (settle()): a stop pressed just
  // before the cable came out is not lost.
  held_ = 0;
  losses_.fetch_add(1, std::memory_order_acq_rel);
  notices_.add(DriverNotice::Level::warning, std::move(text));
  next_open_ = now + kReopenDelayNs;
}

void EvdevReader::apply(const input_event& event, std::int64_t now) {
  if (event.type == EV_SYN) {
    // After SYN_DROPPED the kernel lost events up to the next SYN_REPORT: ignore them and ask
    // the device for its state instead.
    if (event.code == SYN_DROPPED) {
      dropping_ = true;
    } else if (event.code == SYN_REPORT && dropping_) {
      dropping_ = false;
      if (!fifo_) sync_state(now);
    }
    return;
  }
  if (dropping_) return;
  for (const EvdevBinding& b : bindings_) {
    if (b.type != event.type || b.code != event.code) continue;
    const auto i = static_cast<std::size_t>(b.index);
    switch (b.target) {
      case EvdevBinding::Target::input:
        // 1 pressed, 2 auto-repeat (still pressed), 0 released.
        if (event.value != 0) {
          press(std::uint64_t{1} << b.index, now);
        } else {
          held_ &= ~(std::uint64_t{1} << b.index);
        }
        break;
      case EvdevBinding::Target::counter: {
        const std::int32_t step = dial_positions_ && event.code == REL_DIAL
                                      ? evdev_dial_step(dial_last_[i], event.value)
                                      : event.value;
        counts_[i].store(
            counts_[i].load(std::memory_order_relaxed) + static_cast<std::uint32_t>(step),
            std::memory_order_release);
        break;
      }
      case EvdevBinding::Target::analog:
        analog_[i].store(event.value, std::memory_order_release);
        break;
    }
  }
}

void EvdevReader::press(std::uint64_t bits, std::int64_t now) {
  for (std::uint64_t fresh = bits & ~held_; fresh != 0; fresh &= fresh - 1)
    pressed_at_[static_cast<std::size_t>(__builtin_ctzll(fresh))] = now;
  held_ |= bits;
  shown_bits_ |= bits;
  shown_.store(shown_bits_, std::memory_order_release);
}

std::int64_t EvdevReader::settle(std::int64_t now) {
  std::int64_t next = INT64_MAX;
  for (std::uint64_t pending = shown_bits_ & ~held_; pending != 0; pending &= pending - 1) {
    const int n = __builtin_ctzll(pending);
    const std::int64_t due = pressed_at_[static_cast<std::size_t>(n)] + hold_ns_;
    if (now >= due) {
      shown_bits_ &= ~(std::uint64_t{1} << n);
    } else {
      next = std::min(next, due);
    }
  }
  shown_.store(shown_bits_, std::memory_order_release);
  return next;
}

}  // namespace cncd::drivers
