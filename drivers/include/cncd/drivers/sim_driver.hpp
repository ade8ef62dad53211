// The simulated driver: feedback follows the command, optionally through a first-order lag,
// with home switches simulated at set positions and faults, stale feedback, limit switches
// and the estop input injectable from any thread (tests, demos). With [SPINDLE_0] DRIVER = sim
// it also simulates the spindle, and it owns every `sim:NAME` signal address, the panel's too:
// buttons and switches (0/1), counters (a value wrapped to 32 bits), A/B encoders decoded each
// servo period, analog knobs, and the lights (0/1).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/quadrature.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/drivers/spindle_model.hpp"

namespace cncd::drivers {

class SimDriver final : public Driver {
 public:
  // Non-RT. Every joint with a HOME_SEARCH_VEL gets a home switch at motor position
  // HOME_OFFSET (as if the machine powered up with motor and joint positions equal), closed
  // from there on in the search direction, like a cam that a search runs onto. Each joint's
  // `[JOINT_n] SIM_LAG` (seconds) sets its lag.
  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  void enable() override {}
  void disable() override {}
  // RT: positions are in motor units; the first write also sets the simulated position.
  CNCD_RT void write(const JointCommand* commands, int count) noexcept override;
  // RT.
  CNCD_RT void read(JointFeedback* feedback, int count) noexcept override;
  CNCD_RT void read_inputs(MachineInputs& inputs) noexcept override;
  // RT: the simulated spindle takes the command; sim outputs take their values.
  CNCD_RT void write_io(const IoCommand& command) noexcept override;
  // RT: the simulated spindle moves one servo period on; sim inputs give their values.
  CNCD_RT void read_io(IoFeedback& feedback) noexcept override;
  // RT-safe, any thread: names the first joint with an injected fault, else the spindle.
  CNCD_RT bool fault_reason(char* out, std::size_t size) const noexcept override;
  std::uint32_t capabilities() const noexcept override {
    return kCapHomeSwitch | kCapLimitSwitches | kCapEstopInput;
  }
  const char* name() const noexcept override { return "sim"; }

  // The injection API below is for any thread; `index` is the joint's position in
  // configure()'s list, out-of-range indexes are ignored.

  // The simulated probe ([SIM] PROBE_SURFACE_Z and PROBE_X_MIN .. PROBE_Y_MAX): a block of
  // work whose top is at that Z; the probe input is asserted while the point the joints of
  // X, Y and Z put the tool at (motor positions) is inside it. A forced level overrides the
  // model (any thread): 1 asserted, 0 released, -1 the model again.
  void force_probe(int level) noexcept { probe_forced_.store(level); }

  // Feedback of every joint lags the command with this time constant in seconds (0 = exact
  // echo).
  void set_lag(double time_constant_s) noexcept;
  void set_fault(int index, bool fault) noexcept;
  void set_stale(int index, bool stale) noexcept;
  void set_limit(int index, bool min_limit, bool max_limit) noexcept;
  void set_estop_input(bool asserted) noexcept { estop_.store(asserted); }
  // Home switch closed at motor positions >= `position` (direction > 0) or <= `position`
  // (direction < 0); direction 0 removes the switch.
  void set_home_switch(int index, double position, int direction) noexcept;

  // The simulated spindle (any thread). A fault or stale feedback shows in SpindleFeedback
  // until it is injected off again.
  void set_spindle_fault(bool fault) noexcept { spindle_fault_.store(fault); }
  void set_spindle_stale(bool stale) noexcept { spindle_stale_.store(stale); }

  // Signals named `sim:NAME` in the config (any thread, not RT: they look the name up).
  // An output and an input given the same NAME are one signal, wired back to back.
  // The value of a signal (an output as last written, 0/1 for digital ones), or nothing when
  // no address names it.
  std::optional<double> signal_value(std::string_view name) const;
  // Whether a signal is on (value not 0); false when no address names it.
  bool signal_on(std::string_view name) const;
  // Sets a signal the next read_io() reports (a bool gives 0 or 1); false when no address
  // names it. Setting an output is allowed too, and lasts until the servo writes it again.
  bool set_signal(std::string_view name, double value);

  // Any thread: steps of a panel encoder given as two sim signals (A/B) that changed both
  // lines at once between two servo periods, so counted nothing.
  std::uint32_t quadrature_errors(config::PanelCounter which) const noexcept {
    return panel_counters_[static_cast<std::size_t>(which)].errors.load(std::memory_order_relaxed);
  }

 private:
  struct Signal {
    std::string name;
    std::atomic<double> value{0};
  };
  Signal* find(std::string_view name) const;
  CNCD_RT void store(int index, double value) noexcept;
  CNCD_RT double load(int index) const noexcept;
  CNCD_RT void simulate_spindle(IoFeedback& feedback) noexcept;

  struct HomeSwitch {
    std::atomic<double> position{0};
    std::atomic<int> direction{0};
  };
  static bool valid(int index) noexcept { return index >= 0 && index < kMaxJoints; }

  double period_s_ = 0.001;
  std::array<std::atomic<double>, kMaxJoints> lag_s_{};
  std::atomic<bool> estop_{false};
  // The probe model: which of this driver's joints drive X, Y and Z (-1: none) and the block.
  bool probe_model_ = false;
  std::array<int, 3> probe_joint_{-1, -1, -1};
  double probe_top_ = 0;
  double probe_x_min_ = -1e300, probe_x_max_ = 1e300, probe_y_min_ = -1e300, probe_y_max_ = 1e300;
  std::atomic<int> probe_forced_{-1};
  int probe_signal_ = -1;  // [CNCD] PROBE_INPUT = sim:NAME
  std::array<std::atomic<bool>, kMaxJoints> fault_{};
  std::array<std::atomic<bool>, kMaxJoints> stale_{};
  std::array<std::atomic<bool>, kMaxJoints> min_limit_{};
  std::array<std::atomic<bool>, kMaxJoints> max_limit_{};
  std::array<HomeSwitch, kMaxJoints> home_switch_{};

  // Signals: names resolved to indexes at configure(), so the servo thread only indexes.
  std::unique_ptr<Signal[]> signals_;
  std::size_t signal_count_ = 0;
  int flood_ = -1;
  int mist_ = -1;
  template <std::size_t N>
  static constexpr std::array<int, N> none() {
    std::array<int, N> out{};
    out.fill(-1);
    return out;
  }
  std::array<int, kMaxDigitalIo> digital_out_ = none<kMaxDigitalIo>();
  std::array<int, kMaxAnalogIo> analog_out_ = none<kMaxAnalogIo>();
  std::array<int, kMaxDigitalIo> digital_in_ = none<kMaxDigitalIo>();
  std::array<int, kMaxAnalogIo> analog_in_ = none<kMaxAnalogIo>();
  // The panel: signal slots of its inputs, analog knobs and lights (-1: not sim).
  std::array<int, config::kPanelInputs> panel_in_ = none<config::kPanelInputs>();
  std::array<int, config::kPanelAnalogs> panel_analog_ = none<config::kPanelAnalogs>();
  std::array<int, config::kPanelLights> panel_light_ = none<config::kPanelLights>();
  struct PanelCounter {
    int counts = -1;  // COUNTS: the value is the count
    int a = -1;       // A/B: decoded each servo period
    int b = -1;
    QuadratureCounter decoder;  // servo thread
    std::atomic<std::uint32_t> errors{0};
  };
  std::array<PanelCounter, config::kPanelCounters> panel_counters_{};
  CNCD_RT void read_panel(PanelFeedback& panel) noexcept;

  // The simulated spindle; state below is the servo thread's.
  bool spindle_ = false;
  std::atomic<bool> spindle_fault_{false};
  std::atomic<bool> spindle_stale_{false};
  SpindleModel spindle_model_;
  // Servo thread only.
  std::array<double, kMaxJoints> commanded_{};
  std::array<double, kMaxJoints> position_{};
  bool primed_ = false;
};

}  // namespace cncd::drivers
