// Where the step/dir driver's lines go: a GPIO character device (libgpiod 1.6), or a recording
// backend that writes every output transition to an IEEE 1364 value change dump (VCD) and takes
// its input levels from tests. Only the hardware is replaced; the step logic is the same.
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

struct GpioOutput {
  int line = -1;     // line offset on the chip
  std::string name;  // signal name in recordings, e.g. "j0_step"
};

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
                              const std::vector<int>& inputs) = 0;
  // Non-RT. Starts / stops helper threads (the VCD writer); stop() flushes everything recorded.
  virtual void start() {}
  virtual void stop() {}
  // RT, base thread: sets every output (indexed like request()'s outputs) with one bulk
  // request; `time_ns` is CLOCK_MONOTONIC or virtual time, for recordings.
  virtual void write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept = 0;
  // RT, base thread: reads every input (indexed like request()'s inputs) with one bulk request.
  virtual void read_inputs(std::uint8_t* levels) noexcept = 0;
  // Any thread: whether outputs reach pins, so that each base period must happen on time. A
  // recording only needs each transition stamped with its period's time.
  virtual bool drives_pins() const noexcept { return true; }
};

inline constexpr int kVcdLines = 64;

// Records outputs to a VCD file. Lines are "0" .. "63" or "GPIO0" .. "GPIO63". Transitions go
// through a lock-free ring to a writer thread, so the base thread never touches the file.
class VcdBackend final : public GpioBackend {
 public:
  explicit VcdBackend(std::string path);
  ~VcdBackend() override;

  int find_line(const std::string& spec, std::string& error) override;
  std::string request(const std::vector<GpioOutput>& outputs,
                      const std::vector<int>& inputs) override;
  void start() override;
  void stop() override;
  void write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept override;
  void read_inputs(std::uint8_t* levels) noexcept override;
  bool drives_pins() const noexcept override { return false; }

  // Any thread: the electrical level an input line reads from now on.
  void set_input_level(int line, bool high) noexcept;
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
  void drain();
  void writer_loop();

  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<GpioOutput> outputs_;
  std::vector<int> inputs_;
  std::vector<std::uint8_t> last_;
  std::int64_t start_ns_ = -1;      // base thread only: time of the first write
  std::int64_t last_time_ns_ = -1;  // writer thread only
  std::unique_ptr<Transition[]> ring_;
  std::atomic<std::uint64_t> head_{0};  // written by the base thread
  std::atomic<std::uint64_t> tail_{0};  // written by the writer thread
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> running_{false};
  std::thread writer_;
  std::array<std::atomic<bool>, kVcdLines> input_levels_{};
};

// Non-RT. A backend for [GPIO] CHIP: "vcd:PATH" records, anything else names a chip
// ("gpiochip0", "/dev/gpiochip0", a label or a number). nullptr with `error` set on failure.
std::unique_ptr<GpioBackend> make_gpio_backend(const std::string& chip, std::string& error);

}  // namespace cncd::drivers
