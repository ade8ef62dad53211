// Panel inputs from Linux input event devices (`evdev:DEVICE:CODE`, docs/drivers.md, "USB
// pendants (evdev)"): a USB pendant, jog wheel or keypad read as evtest shows it, with no
// kernel driver of ours. KEY_* and BTN_* codes are buttons (1 or 2 pressed, 0 released),
// REL_* codes add their values to a 32-bit counter that wraps (a Contour Shuttle's REL_DIAL,
// which gives positions, its steps: evdev_dial_step()), ABS_* codes are analog values.
//
// Each device has its own reader thread (non-RT) that opens it without blocking, reads whole
// `struct input_event` records (a FIFO may split one across writes) and publishes the result
// in atomics; the servo thread's read_io() only copies them. A device that is missing at
// start, unplugged, or a FIFO whose writer closed is opened again every 250 ms; meanwhile its
// buttons read released and the driver has a notice for the daemon to log (take_notice()).
// Every press shows for at least the debounce time and a margin, even when its release came
// in the same read or the device was lost right after, so that a quick stop is never missed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

class EvdevReader;
class EvdevNotices;

// Whether a [PANEL] signal is an `evdev:` address (then make_drivers adds an evdev driver).
bool uses_evdev(const config::MachineConfig& config);

// Contour Design's ShuttleXpress and ShuttlePRO send where the 8-bit counter of their jog dial
// stands as REL_DIAL, not a step; this turns one such position into the step since `last`
// (-1: none yet, and then no step: where the counter stood before is unknown). The difference
// wraps, so a position of 0, which the kernel never passes on (a relative value of 0 says
// nothing), only delays its step to the next position.
inline std::int32_t evdev_dial_step(int& last, std::int32_t value) {
  const int position = value & 0xff;
  const int previous = last;
  last = position;
  if (previous < 0) return 0;
  return static_cast<std::int8_t>(static_cast<std::uint8_t>(position - previous));
}

class EvdevDriver final : public Driver {
 public:
  EvdevDriver();
  ~EvdevDriver() override;

  // Non-RT. Binds the [PANEL] inputs, counters and analog knobs given as `evdev:` addresses
  // to one reader per DEVICE. Refuses, naming the key: joints, a code that is no KEY_, BTN_,
  // REL_ or ABS_ name of <linux/input-event-codes.h> or does not fit the key (a button needs
  // KEY_/BTN_, a COUNTS input REL_, an ANALOG input ABS_), evdev quadrature or lights, and a
  // DEVICE that exists but is neither a character device nor a FIFO (a character device must
  // be an input event device this user may read). A missing DEVICE is not refused.
  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  // Non-RT: start and stop the reader threads.
  void enable() override;
  void disable() override;
  CNCD_RT void write(const JointCommand* /*commands*/, int /*count*/) noexcept override {}
  CNCD_RT void read(JointFeedback* /*feedback*/, int /*count*/) noexcept override {}
  // RT: the levels, counters (counter_bits 32) and analog values of the evdev panel signals.
  CNCD_RT void read_io(IoFeedback& feedback) noexcept override;
  // Non-RT: devices opened, missing and lost, oldest first.
  bool take_notice(DriverNotice& out) override;
  std::uint32_t capabilities() const noexcept override { return 0; }
  const char* name() const noexcept override { return "evdev"; }

  // Any thread: how many times a device was lost (end of stream or a read error), all devices
  // together.
  std::uint64_t losses() const noexcept;

 private:
  std::unique_ptr<EvdevNotices> notices_;  // outlives the readers that write it
  std::vector<std::unique_ptr<EvdevReader>> readers_;
};

}  // namespace cncd::drivers
