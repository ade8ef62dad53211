// The servo-period cost of the panel ([PANEL]): the servo loop in a tight loop at a 1 kHz
// period, with every panel input wired and toggling, the counters and analog knobs changing
// and the MPG jogging X, against the same loop without a panel jogging X from a client's jog
// command, measured in the same run. Prints figures; never fails on timing.
//
//   cncd_panel_bench [CYCLES] [ROUNDS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <utility>
#include <vector>

#include "bench_mill.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "cncd/motion/servo_loop.hpp"

namespace {

using namespace cncd;
using config::PanelInput;

config::MachineConfig bench_mill() {
  return bench::three_axis_mill();
}

config::SignalAddress wired(const char* code) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::evdev;
  a.device = "/dev/input/bench";
  a.code = code;
  return a;
}

// Every input the mill can have, the MPG and three knobs as counters, three analog knobs.
config::MachineConfig panel_mill(config::PanelConfig::MpgMode mode) {
  config::MachineConfig c = bench_mill();
  auto& p = c.panel;
  p.present = true;
  p.debounce_ms = 10;
  p.mpg_mode = mode;
  for (int i = 0; i < config::kPanelInputs; ++i) {
    const int axis = (i - static_cast<int>(PanelInput::jog_plus_x)) % config::kPanelAxes;
    if (i < static_cast<int>(PanelInput::jog_plus_x) || axis < 3)
      p.inputs[static_cast<std::size_t>(i)] = wired("KEY_A");
  }
  p.mpg.counts = wired("REL_DIAL");
  for (auto& knob : p.knobs) {
    knob.encoder.counts = wired("REL_WHEEL");
    knob.analog = wired("ABS_X");
  }
  return c;
}

// The panel's signals as a driver of no joints reports them: the MPG on X, enabled, turning
// back and forth; the buttons pressed in turn; knobs turning.
class PanelSource final : public drivers::Driver {
 public:
  std::string configure(const config::MachineConfig&, const std::vector<int>&) override {
    return "";
  }
  void enable() override {}
  void disable() override {}
  void write(const drivers::JointCommand*, int) noexcept override {}
  void read(drivers::JointFeedback*, int) noexcept override {}
  void write_io(const drivers::IoCommand& command) noexcept override { lights_ = command.panel; }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    ++n_;
    constexpr std::uint64_t kMpg = std::uint64_t{1} << static_cast<int>(PanelInput::mpg_axis_x) |
                                   std::uint64_t{1} << static_cast<int>(PanelInput::mpg_enable) |
                                   std::uint64_t{1} << static_cast<int>(PanelInput::mpg_step_10);
    // One button down 40 periods in turn, the others up.
    const std::uint64_t button = std::uint64_t{1} << ((n_ / 40) % 9);
    feedback.panel.inputs = kMpg | button;
    mpg_ += (n_ / 1000) % 2 == 0 ? 3 : -3;
    feedback.panel.counts = {mpg_, static_cast<std::uint32_t>(n_ / 7),
                             static_cast<std::uint32_t>(n_ / 11) & 0xFFFF,
                             static_cast<std::uint32_t>(n_ / 13)};
    feedback.panel.counter_bits = {32, 32, 16, 32};
    feedback.panel.analog = {static_cast<double>(n_ % 10), 5, 2.5};
  }
  std::uint32_t capabilities() const noexcept override { return 0; }
  const char* name() const noexcept override { return "panel"; }
  std::uint32_t lights() const { return lights_; }

 private:
  std::uint64_t n_ = 0;
  std::uint32_t mpg_ = 0;
  std::uint32_t lights_ = 0;
};

struct Loop {
  Loop(const config::MachineConfig& c, bool panel) : config(c) {
    joints = {0, 1, 2};
    sim.configure(config, joints);
    std::vector<motion::DriverBinding> bindings{{&sim, joints}};
    if (panel) bindings.push_back({&source, {}});
    loop = std::make_unique<motion::ServoLoop>(config, std::move(bindings));
    send(motion::Command::Kind::reset_estop);
    send(motion::Command::Kind::on);
  }
  void send(motion::Command::Kind kind, int axis = 0, double velocity = 0) {
    motion::Command c;
    c.kind = kind;
    c.axis = axis;
    c.velocity = velocity;
    loop->commands().push(c);
    loop->cycle(0);
  }
  // ns per cycle over `cycles` periods; without a panel a client's jog reverses every second.
  double run(long cycles, bool client_jog) {
    motion::Event event;
    const auto start = std::chrono::steady_clock::now();
    for (long i = 0; i < cycles; ++i) {
      if (client_jog && i % 1000 == 0) {
        motion::Command c;
        c.kind = motion::Command::Kind::jog_start;
        c.velocity = (i / 1000) % 2 == 0 ? 7.5 : -7.5;
        loop->commands().push(c);
      }
      loop->cycle(0);
      while (loop->events().pop(event)) {
      }
    }
    const auto ns =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start);
    return ns.count() / static_cast<double>(cycles);
  }
  config::MachineConfig config;
  std::vector<int> joints;
  drivers::SimDriver sim;
  PanelSource source;
  std::unique_ptr<motion::ServoLoop> loop;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const long cycles = argc > 1 ? std::atol(argv[1]) : 200'000;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 7;
  Loop reference(bench_mill(), false);
  Loop position(panel_mill(config::PanelConfig::MpgMode::position), true);
  Loop velocity(panel_mill(config::PanelConfig::MpgMode::velocity), true);
  std::vector<double> ref_ns;
  std::vector<double> pos_ns;
  std::vector<double> vel_ns;
  // Interleaved rounds, so that a busy machine weighs on all three alike.
  for (int r = 0; r < rounds; ++r) {
    ref_ns.push_back(reference.run(cycles, true));
    pos_ns.push_back(position.run(cycles, false));
    vel_ns.push_back(velocity.run(cycles, false));
  }
  const double period_ns = 1e6;
  const double ref = median(ref_ns);
  std::printf("servo period                  1000 us (1 kHz), %ld cycles x %d rounds, medians\n",
              cycles, rounds);
  std::printf("reference (no panel, jog)     %8.1f ns/period\n", ref);
  for (const auto& [name, ns] : {std::pair{"panel, MPG position mode", median(pos_ns)},
                                 std::pair{"panel, MPG velocity mode", median(vel_ns)}}) {
    const double cost = ns - ref;
    std::printf("%-29s %8.1f ns/period: panel %+.1f ns = %.4f %% of the period\n", name, ns, cost,
                100.0 * cost / period_ns);
  }
  const motion::Status s = position.loop->status();
  std::printf("(MPG moved X to %.3f, %s; presses of CYCLE_START %u)\n", s.commanded[0],
              s.panel.mpg_jogging ? "jogging" : "at rest", s.panel.presses[0]);
  return 0;
}
