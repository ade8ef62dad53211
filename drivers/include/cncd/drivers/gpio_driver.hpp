// Step/dir joints on GPIO lines (DRIVER = gpio). A base thread at [EMCMOT] BASE_PERIOD runs
// the step generators and writes all output lines of the chip with one bulk request per period;
// it samples and debounces the switch inputs. The servo thread meets it only through seqlock
// mailboxes (commands) and atomics (step counts, switches).
//
// The same base thread drives the `gpio:LINE` signals (coolant, digital outputs and inputs)
// and a spindle with [SPINDLE_0] DRIVER = gpio: enable and direction lines, a PWM line whose
// duty follows the speed ramped at ACCELERATION, and an optional quadrature encoder. The
// panel's `gpio:` signals too: buttons and switches (sampled each base period, undebounced:
// the servo thread debounces them), lights, and the A/B encoders of the MPG and the override
// knobs, decoded in the base thread into 32-bit counts the servo thread reads from atomics.
// Without BASE_PERIOD there is no base thread, and configure() fails saying so.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/gpio_backend.hpp"
#include "cncd/drivers/quadrature.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/drivers/seqlock.hpp"

namespace cncd::drivers {

class Stepgen;
class Pwmgen;
class QuadratureDecoder;

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
  // RT: hands the spindle and output commands to the base thread.
  CNCD_RT void write_io(const IoCommand& command) noexcept override;
  // RT: the spindle's speed (encoder or ramp) and the debounced digital inputs.
  CNCD_RT void read_io(IoFeedback& feedback) noexcept override;
  std::uint32_t capabilities() const noexcept override { return capabilities_; }
  const char* name() const noexcept override { return "gpio"; }

  // Non-RT, before enable(): no base thread; the caller advances time with run_base_period().
  // Tests and benchmarks use it to run the driver in virtual time.
  void use_manual_clock(bool manual) { manual_clock_ = manual; }
  // Non-RT, before enable(): a recording backend's base thread wakes once per base period, as
  // for pins, instead of once per servo period (tests of the real-time loop use it).
  void pace_recording_in_real_time(bool real_time) { real_time_recording_ = real_time; }
  // RT, base thread (or the caller with a manual clock): one base period at `time_ns`.
  void run_base_period(std::int64_t time_ns) noexcept;
  // Any thread: the step count of the joint at `index` (position in configure()'s list).
  std::int64_t step_count(int index) const noexcept;
  GpioBackend* backend() noexcept { return backend_.get(); }
  // Any thread: steps of a panel encoder that changed both lines between two base periods, so
  // counted nothing (the wheel turned faster than the base thread samples).
  std::uint32_t quadrature_errors(config::PanelCounter which) const noexcept {
    return panel_errors_[static_cast<std::size_t>(which)].load(std::memory_order_relaxed);
  }
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
  // Servo thread -> base thread.
  struct IoBlock {
    bool spindle_enable = false;
    bool spindle_reverse = false;
    double spindle_rpm = 0;
    std::uint64_t spindle_sequence = 0;
    bool flood = false;
    bool mist = false;
    std::uint32_t digital = 0;
    std::uint32_t panel = 0;  // the lights
  };
  // Base thread -> servo thread.
  struct SpindleState {
    double rpm = 0;  // >= 0
    double revolutions = 0;
    std::int64_t time_ns = 0;        // the base period that counted it
    std::uint64_t acknowledged = 0;  // the spindle command that base period ran with
  };
  struct OutputLine {
    int output = -1;  // index into output_levels_, -1 = none
    bool active_low = false;
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

  // A panel encoder's lines: indexes into input_levels_ (-1: not on this driver).
  struct PanelEncoder {
    int a = -1;
    int b = -1;
    bool a_low = false;
    bool b_low = false;
    QuadratureCounter decoder;  // base thread
  };

  void base_loop() noexcept;
  void sample_inputs(std::int64_t time_ns) noexcept;
  CNCD_RT void sample_panel_encoders() noexcept;
  std::string configure_panel(
      const config::MachineConfig& machine,
      const std::function<int(const config::SignalAddress&, const std::string&)>& input,
      const std::function<OutputLine(const config::SignalAddress&, const std::string&)>& output);
  bool input(int index) const noexcept;
  std::string configure_io(const config::MachineConfig& machine, std::vector<GpioOutput>& outputs,
                           std::vector<GpioLine>& input_lines,
                           std::vector<std::pair<bool, int>>& input_specs, std::set<int>& used);
  CNCD_RT void run_io(double dt, std::int64_t time_ns) noexcept;
  CNCD_RT void set_output(const OutputLine& line, bool on) noexcept;

  std::unique_ptr<GpioBackend> backend_;
  std::vector<JointLines> joints_;
  std::vector<Stepgen> stepgens_;
  std::vector<bool> primed_;
  std::unique_ptr<Input[]> inputs_;
  std::size_t input_count_ = 0;
  int estop_input_ = -1;
  int probe_input_ = -1;
  // The probe, undebounced: its level now, and whether it was asserted in any base period since
  // the servo thread last read it (a touch shorter than a servo period is not lost).
  std::atomic<bool> probe_level_{false};
  std::atomic<bool> probe_touched_{false};
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
  std::atomic<std::uint64_t> periods_{0};
  // The base thread has stopped when this many servo periods in a row have run without one of
  // its periods. Counted in servo periods that ran, not in wall time: a virtual machine now and
  // then stalls every thread, SCHED_FIFO ones too, for tens of milliseconds, and after such a
  // stall the servo thread may wake before the base thread; the generator catches up (within
  // STEPGEN_MAXVEL, watched by the following error), so only a base thread that stays silent
  // while the servo thread runs is a fault.
  static constexpr std::int64_t kStaleServoPeriods = 20;
  std::int64_t stale_reads_ = kStaleServoPeriods;  // servo thread's side
  std::uint64_t seen_periods_ = 0;
  std::int64_t silent_reads_ = 0;
  bool stale_ = false;
  std::atomic<std::int64_t> max_late_ns_{0};
  std::atomic<std::int64_t> total_late_ns_{0};

  // Signals and the spindle.
  OutputLine flood_;
  OutputLine mist_;
  std::array<OutputLine, kMaxDigitalIo> digital_out_{};
  std::array<int, kMaxDigitalIo> digital_in_{};       // index into inputs_, -1 = none
  std::array<int, config::kPanelInputs> panel_in_{};  // index into inputs_, -1 = none
  std::array<OutputLine, config::kPanelLights> panel_light_{};
  std::array<PanelEncoder, config::kPanelCounters> panel_encoders_{};
  std::array<std::atomic<std::uint32_t>, config::kPanelCounters> panel_counts_{};
  std::array<std::atomic<std::uint32_t>, config::kPanelCounters> panel_errors_{};
  bool spindle_ = false;
  OutputLine spindle_enable_;
  OutputLine spindle_dir_;
  OutputLine spindle_pwm_;
  double spindle_max_rpm_ = 0;
  double pwm_min_duty_ = 0;
  double spindle_acceleration_ = 0;  // rpm/s, 0 = at once
  int encoder_a_ = -1;               // index into input_levels_, -1 = no encoder
  int encoder_b_ = -1;
  int encoder_index_ = -1;
  std::unique_ptr<Pwmgen> pwmgen_;
  std::unique_ptr<QuadratureDecoder> encoder_;
  Seqlock<IoBlock> io_mailbox_;
  IoBlock io_{};  // base thread's copy of the latest command
  std::uint64_t io_version_ = 0;
  double ramp_rpm_ = 0;  // base thread: signed, negative in reverse
  Seqlock<SpindleState> spindle_state_;
  SpindleState spindle_feedback_{};  // servo thread: kept while the base thread publishes

  bool manual_clock_ = false;
  bool real_time_recording_ = false;
  std::atomic<bool> running_{false};
  std::thread base_thread_;
};

}  // namespace cncd::drivers
