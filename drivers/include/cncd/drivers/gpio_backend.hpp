// Where the step/dir driver's lines go: a GPIO character device (libgpiod 1.6), or a recording
// backend that writes every transition of its output and input lines to an IEEE 1364 value
// change dump (VCD) and takes its input levels from tests. Only the hardware is replaced; the
// step logic is the same.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace cncd::drivers {

struct GpioLine {
  int line = -1;     // line offset on the chip
  std::string name;  // signal name in recordings, e.g. "j0_step", "cycle_start"
};
using GpioOutput = GpioLine;

class GpioBackend {
 public:
  virtual ~GpioBackend() = default;
  GpioBackend() = default;
  GpioBackend(const GpioBackend&) = delete;
  GpioBackend& operator=(const GpioBackend&) = delete;

  // Non-RT. The offset of a line given as an offset ("17") or a name ("GPIO17"), or -1 with
  // `error` set.
  virtual int find_line(const std::string& spec, std::string& error) = 0;
  // Non-RT. Claims the lines, outputs starting low; returns "" or what went wrong.
  virtual std::string request(const std::vector<GpioOutput>& outputs,
                              const std::vector<GpioLine>& inputs) = 0;
  // Non-RT. Starts / stops helper threads (the VCD writer); stop() flushes everything recorded.
  virtual void start() {}
  virtual void stop() {}
  // RT, base thread: sets every output (indexed like request()'s outputs) with one bulk
  // request; `time_ns` is CLOCK_MONOTONIC or virtual time, for recordings.
  virtual void write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept = 0;
  // RT, base thread: reads every input (indexed like request()'s inputs) with one bulk request,
  // in the base period at `time_ns` (the time write_outputs() was given).
  virtual void read_inputs(std::uint8_t* levels, std::int64_t time_ns) noexcept = 0;
  // Any thread: whether outputs reach pins, so that each base period must happen on time. A
  // recording only needs each transition stamped with its period's time.
  virtual bool drives_pins() const noexcept { return true; }
};

inline constexpr int kVcdLines = 64;

// Records outputs and inputs (their electrical levels, as read each base period) to a VCD
// file, on one time axis: a button's press and the steps it caused. Lines are "0" .. "63" or
// "GPIO0" .. "GPIO63". Transitions go through a lock-free ring to a writer thread, so the base
// thread never touches the file.
class VcdBackend final : public GpioBackend {
 public:
  explicit VcdBackend(std::string path);
  ~VcdBackend() override;

  int find_line(const std::string& spec, std::string& error) override;
  std::string request(const std::vector<GpioOutput>& outputs,
                      const std::vector<GpioLine>& inputs) override;
  void start() override;
  void stop() override;
  void write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept override;
  void read_inputs(std::uint8_t* levels, std::int64_t time_ns) noexcept override;
  bool drives_pins() const noexcept override { return false; }

  // Any thread: the electrical level an input line reads from now on.
  void set_input_level(int line, bool high) noexcept;

  // Input levels over time, counted in base periods rather than wall time, so that a test
  // feeds an encoder exactly however late the base thread runs: each step sets `line` to
  // `high` at a base period's read, and the next step comes `hold_periods` base periods later
  // (0: at the same read, both lines of an encoder at once).
  struct InputStep {
    int line = 0;
    bool high = false;
    std::uint32_t hold_periods = 1;
  };
  static constexpr std::size_t kFeedSize = 1u << 16;
  // One thread at a time: queues `steps` after those not yet applied; false (nothing queued)
  // when they do not fit.
  bool feed_inputs(const std::vector<InputStep>& steps);
  // Any thread: the steps applied so far.
  std::uint64_t inputs_fed() const noexcept { return fed_.load(std::memory_order_acquire); }
  // Transitions lost because the ring was full (the writer thread fell behind).
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  struct Transition {
    std::int64_t time_ns;
    std::uint32_t output;
    std::uint32_t level;
  };
  static constexpr std::size_t kRingSize = 1u << 18;
  bool pop(Transition& out) noexcept;
  void record(std::size_t signal, std::uint8_t level, std::int64_t time_ns) noexcept;
  void apply_feed() noexcept;
  void drain();
  void writer_loop();

  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<GpioOutput> outputs_;
  std::vector<GpioLine> inputs_;
  std::vector<std::uint8_t> last_;  // outputs, then inputs: the level recorded last
  std::int64_t start_ns_ = -1;      // base thread only: time of the first write
  std::int64_t last_time_ns_ = -1;  // writer thread only
  std::unique_ptr<Transition[]> ring_;
  std::atomic<std::uint64_t> head_{0};  // written by the base thread
  std::atomic<std::uint64_t> tail_{0};  // written by the writer thread
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> running_{false};
  std::thread writer_;
  std::array<std::atomic<bool>, kVcdLines> input_levels_{};
  std::unique_ptr<InputStep[]> feed_;
  std::atomic<std::uint64_t> feed_head_{0};  // written by feed_inputs()
  std::atomic<std::uint64_t> fed_{0};        // written by the base thread
  std::uint32_t hold_left_ = 0;              // base thread only
};

// Non-RT. A backend for [GPIO] CHIP: "vcd:PATH" records, anything else names a chip
// ("gpiochip0", "/dev/gpiochip0", a label or a number). nullptr with `error` set on failure.
std::unique_ptr<GpioBackend> make_gpio_backend(const std::string& chip, std::string& error);

}  // namespace cncd::drivers
