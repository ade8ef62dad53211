// One input event device of the evdev driver: a thread that reads its `struct input_event`
// records and publishes button levels, counters and analog values in atomics for the servo
// thread.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cncd/config/panel_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/evdev_driver.hpp"
#include "cncd/drivers/rt.hpp"

struct input_event;

namespace cncd::drivers {

// What one event code of a device drives.
struct EvdevBinding {
  enum class Target : std::uint8_t { input, counter, analog };
  std::uint16_t type = 0;  // EV_KEY, EV_REL or EV_ABS
  std::uint16_t code = 0;
  Target target = Target::input;
  int index = 0;  // config::PanelInput, PanelCounter or PanelAnalog
};

// Notices of the driver's reader threads, kept until the daemon takes them. Bounded: a device
// that comes and goes all day must not grow it without end.
class EvdevNotices {
 public:
  void add(DriverNotice::Level level, std::string text);
  bool take(DriverNotice& out);

 private:
  static constexpr std::size_t kMax = 64;
  std::mutex mutex_;
  std::deque<DriverNotice> queue_;
  std::uint64_t dropped_ = 0;
};

class EvdevReader {
 public:
  // `hold_ns`: the shortest time a press stays visible (the debounce time and a margin), so
  // that a press and its release read in one burst still reach the servo thread.
  EvdevReader(std::string path, std::vector<EvdevBinding> bindings, std::int64_t hold_ns,
              EvdevNotices& notices);
  ~EvdevReader();
  EvdevReader(const EvdevReader&) = delete;
  EvdevReader& operator=(const EvdevReader&) = delete;

  // Non-RT: start and stop the reader thread (stop() waits for it; both may be repeated).
  void start();
  void stop();
  // RT: the levels, counters and analog values this device drives, into `out`.
  CNCD_RT void publish(PanelFeedback& out) const noexcept;
  // Any thread: times the device was lost (end of stream or a read error).
  std::uint64_t losses() const noexcept { return losses_.load(std::memory_order_acquire); }
  const std::string& path() const { return path_; }

 private:
  void run();
  bool open_device(std::int64_t now);
  void sync_state(std::int64_t now);
  void drain(std::int64_t now);
  void lose(const std::string& why, std::int64_t now);
  void apply(const input_event& event, std::int64_t now);
  void press(std::uint64_t bits, std::int64_t now);
  // Clears the shown bits released long enough after their press; returns when the next one
  // is due (INT64_MAX: none).
  std::int64_t settle(std::int64_t now);

  const std::string path_;
  const std::vector<EvdevBinding> bindings_;
  const std::int64_t hold_ns_;
  EvdevNotices& notices_;
  std::uint64_t input_mask_ = 0;
  std::uint32_t counter_mask_ = 0;
  std::uint32_t analog_mask_ = 0;

  // Written by the reader thread, read by the servo thread.
  std::atomic<std::uint64_t> shown_{0};
  std::array<std::atomic<std::uint32_t>, config::kPanelCounters> counts_{};
  std::array<std::atomic<double>, config::kPanelAnalogs> analog_{};
  std::atomic<std::uint64_t> losses_{0};
  static_assert(std::atomic<double>::is_always_lock_free);
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

  // The reader thread's own.
  int fd_ = -1;
  bool fifo_ = false;
  bool dial_positions_ = false;  // a Contour Shuttle: REL_DIAL values are positions
  std::array<int, config::kPanelCounters> dial_last_{};
  std::uint64_t held_ = 0;  // keys down as the device last said
  std::uint64_t shown_bits_ = 0;
  std::array<std::int64_t, config::kPanelInputs> pressed_at_{};
  std::vector<unsigned char> buffer_;
  std::size_t have_ = 0;   // bytes of a partial record at the buffer's start
  bool dropping_ = false;  // after SYN_DROPPED, until the next SYN_REPORT
  bool absent_reported_ = false;
  std::int64_t next_open_ = 0;

  int wake_fd_ = -1;  // an eventfd: stop() writes it to end poll()
  int wake_error_ = 0;
  std::thread thread_;
};

}  // namespace cncd::drivers
