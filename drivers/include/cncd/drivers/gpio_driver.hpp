// Step/dir joints on GPIO lines (DRIVER = gpio). A base thread at [EMCMOT] BASE_PERIOD runs
// the step generators and writes all output lines of the chip with one bulk request per period;
// it samples and debounces the switch inputs. The servo thread meets it only through a seqlock
// mailbox (commands) and atomics (step counts, switches).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/gpio_backend.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/drivers/seqlock.hpp"

namespace cncd::drivers {

class Stepgen;

class GpioDriver final : public Driver {
 public:
  GpioDriver();
  ~GpioDriver() override;

  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  void enable() override;
  void disable() override;
  CNCD_RT void write(const JointCommand* commands, int count) noexcept override;
  CNCD_RT void read(JointFeedback* feedback, int count) noexcept override;
  CNCD_RT void read_inputs(MachineInputs& inputs) noexcept override;
  std::uint32_t capabilities() const noexcept override { return capabilities_; }
  const char* name() const noexcept override { return "gpio"; }

  // Non-RT, before enable(): no base thread; the caller advances time with run_base_period().
  // Tests and benchmarks use it to run the driver in virtual time.
  void use_manual_clock(bool manual) { manual_clock_ = manual; }
  // RT, base thread (or the caller with a manual clock): one base period at `time_ns`.
  void run_base_period(std::int64_t time_ns) noexcept;
  // Any thread: the step count of the joint at `index` (position in configure()'s list).
  std::int64_t step_count(int index) const noexcept;
  GpioBackend* backend() noexcept { return backend_.get(); }
  std::int64_t base_period_ns() const noexcept { return base_period_ns_; }

  // Any thread: how late the base thread woke, over all periods so far.
  struct BaseStats {
    std::uint64_t periods = 0;
    std::int64_t max_late_ns = 0;
    double mean_late_ns = 0;
  };
  BaseStats base_stats() const noexcept;

 private:
  struct Input {
    int backend_index = -1;
    bool active_low = false;
    int debounce_ticks = 1;
    int pending_ticks = 0;
    bool state = false;  // base thread's debounced state
    std::atomic<bool> published{false};
  };
  struct CommandBlock {
    std::array<double, kMaxJoints> position{};
    std::array<double, kMaxJoints> velocity{};
    std::array<bool, kMaxJoints> enable{};
  };
  struct JointLines {
    double scale = 1;
    int step_output = -1;
    int dir_output = -1;
    int enable_output = -1;
    bool enable_active_low = false;
    int home = -1;  // index into inputs_, -1 = none
    int min_limit = -1;
    int max_limit = -1;
  };

  void base_loop() noexcept;
  void sample_inputs() noexcept;
  bool input(int index) const noexcept;

  std::unique_ptr<GpioBackend> backend_;
  std::vector<JointLines> joints_;
  std::vector<Stepgen> stepgens_;
  std::vector<bool> primed_;
  std::unique_ptr<Input[]> inputs_;
  std::size_t input_count_ = 0;
  int estop_input_ = -1;
  int probe_input_ = -1;
  std::vector<std::uint8_t> output_levels_;
  std::vector<std::uint8_t> input_levels_;
  std::uint32_t capabilities_ = 0;
  std::int64_t base_period_ns_ = 0;
  std::int64_t servo_period_ns_ = 0;
  int rt_priority_ = 0;

  Seqlock<CommandBlock> mailbox_;
  CommandBlock command_{};  // base thread's copy of the latest command
  std::uint64_t command_version_ = 0;
  double since_command_s_ = 0;
  std::array<std::atomic<std::int64_t>, kMaxJoints> counts_{};
  std::atomic<std::int64_t> last_period_ns_{0};
  std::atomic<std::uint64_t> periods_{0};
  std::atomic<std::int64_t> max_late_ns_{0};
  std::atomic<std::int64_t> total_late_ns_{0};

  bool manual_clock_ = false;
  std::atomic<bool> running_{false};
  std::thread base_thread_;
};

}  // namespace cncd::drivers
