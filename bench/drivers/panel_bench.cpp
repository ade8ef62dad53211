// What the panel costs the drivers on this machine: write_io + read_io a servo period with a
// full [PANEL] (every input, the MPG and three knobs as A/B encoders, the lights) against the
// same driver without one, on sim and gpio; and the gpio base period with the four encoders
// decoded in it. Prints figures only; timing never fails anything.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/gpio_driver.hpp"
#include "cncd/drivers/sim_driver.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cncd;
using Clock = std::chrono::steady_clock;
using Kind = config::SignalAddress::Kind;

config::MachineConfig load(const fs::path& dir, const std::string& vcd) {
  std::ofstream(dir / "bench.ini")
      << "[EMCMOT]\nSERVO_PERIOD = 1000000\nBASE_PERIOD = 25000\n[TRAJ]\nCOORDINATES = XYZ\n"
         "[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n[GPIO]\nCHIP = vcd:"
      << vcd << "\n";
  for (int j = 0; j < 3; ++j) {
    std::ofstream(dir / "bench.ini", std::ios::app)
        << "[AXIS_"
        << "XYZ"[j] << "]\n[JOINT_" << j << "]\nDRIVER = gpio\nSCALE = 100\n"
        << "STEP_LINE = " << 58 + 2 * j << "\nDIR_LINE = " << 59 + 2 * j << "\n";
  }
  auto result = config::load_machine_config(dir / "bench.ini");
  if (!result.ok()) {
    for (const auto& p : result.problems)
      std::fprintf(stderr, "%s\n", p.to_string().c_str());
    std::exit(1);
  }
  return *result.config;
}

config::SignalAddress address(Kind kind, int n) {
  config::SignalAddress a;
  a.kind = kind;
  a.line = std::to_string(n);
  a.name = "panel" + std::to_string(n);
  a.text = "bench " + std::to_string(n);
  return a;
}

// Every panel input on lines or signals 0 .. 39, the four encoders' A/B on 40 .. 47, the
// lights on 48 .. 52, and (sim only) the three analog knobs.
void add_panel(config::MachineConfig& c, Kind kind) {
  config::PanelConfig& p = c.panel;
  p.present = true;
  for (int i = 0; i < config::kPanelInputs; ++i)
    p.inputs[static_cast<std::size_t>(i)] = address(kind, i);
  p.mpg.a = address(kind, 40);
  p.mpg.b = address(kind, 41);
  for (int k = 0; k < config::kPanelAnalogs; ++k) {
    auto& knob = p.knobs[static_cast<std::size_t>(k)];
    knob.encoder.a = address(kind, 42 + 2 * k);
    knob.encoder.b = address(kind, 43 + 2 * k);
    if (kind == Kind::sim) knob.analog = address(kind, 53 + k);
  }
  for (int l = 0; l < config::kPanelLights; ++l)
    p.lights[static_cast<std::size_t>(l)] = address(kind, 48 + l);
}

// Mean ns of write_io + read_io on `plain` and on `panel`, interleaved; `between` runs after
// each period of both (the gpio base periods, outside the timing).
template <typename Between>
void cost(const char* name, drivers::Driver& plain, drivers::Driver& panel, Between between) {
  constexpr int kPeriods = 200'000;
  drivers::IoCommand io;
  std::int64_t plain_ns = 0, panel_ns = 0;
  for (int i = 0; i < kPeriods; ++i) {
    io.panel = static_cast<std::uint32_t>(i) & 0x1fu;
    drivers::IoFeedback a, b;
    const auto t0 = Clock::now();
    plain.write_io(io);
    plain.read_io(a);
    const auto t1 = Clock::now();
    panel.write_io(io);
    panel.read_io(b);
    const auto t2 = Clock::now();
    plain_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
    panel_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count();
    between(i);
  }
  const double base = static_cast<double>(plain_ns) / kPeriods;
  const double with = static_cast<double>(panel_ns) / kPeriods;
  std::printf(
      "%-4s write_io+read_io %6.1f ns; with a full panel (%d inputs, 4 encoders, 5 lights) "
      "%6.1f ns: %+.1f ns = %.4f %% of a 1 ms servo period\n",
      name, base, config::kPanelInputs, with, with - base, (with - base) / 1e6 * 100);
}

}  // namespace

int main() {
  std::string pattern = (fs::temp_directory_path() / "cncd-panel-bench-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) return 1;
  const fs::path dir = pattern;
  {
    const auto plain = load(dir, (dir / "a.vcd").string());
    auto with = plain;
    add_panel(with, Kind::sim);
    drivers::SimDriver a, b;
    if (const auto e = a.configure(plain, {}) + b.configure(with, {}); !e.empty()) {
      std::printf("sim: %s\n", e.c_str());
      return 1;
    }
    // The wheel turns one count a period: the decoder works every time.
    cost("sim", a, b, [&](int i) {
      const int phase = i % 4;
      b.set_signal("panel40", phase == 1 || phase == 2);
      b.set_signal("panel41", phase == 2 || phase == 3);
    });
  }
  {
    const auto plain = load(dir, (dir / "plain.vcd").string());
    auto with = load(dir, (dir / "panel.vcd").string());
    add_panel(with, Kind::gpio);
    drivers::GpioDriver a, b;
    a.use_manual_clock(true);
    b.use_manual_clock(true);
    if (const auto e = a.configure(plain, {0, 1, 2}) + b.configure(with, {0, 1, 2}); !e.empty()) {
      std::printf("gpio: %s\n", e.c_str());
      return 1;
    }
    a.enable();
    b.enable();
    auto* vcd = dynamic_cast<drivers::VcdBackend*>(b.backend());
    std::int64_t now = 0, plain_base_ns = 0, panel_base_ns = 0, base_periods = 0;
    cost("gpio", a, b, [&](int i) {
      // 40 base periods a servo period at 25 us, the MPG turning a count every 10 of them.
      for (int k = 0; k < 40; ++k) {
        if (k % 10 == 0) {
          const int phase = (i * 4 + k / 10) % 4;
          vcd->set_input_level(40, phase == 1 || phase == 2);
          vcd->set_input_level(41, phase == 2 || phase == 3);
        }
        now += 25'000;
        const auto t0 = Clock::now();
        a.run_base_period(now);
        const auto t1 = Clock::now();
        b.run_base_period(now);
        const auto t2 = Clock::now();
        plain_base_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
        panel_base_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count();
        ++base_periods;
      }
    });
    const double base = static_cast<double>(plain_base_ns) / static_cast<double>(base_periods);
    const double with_panel =
        static_cast<double>(panel_base_ns) / static_cast<double>(base_periods);
    std::printf(
        "gpio base period (recording backend) %6.1f ns; with the panel's %d lines sampled and 4 "
        "encoders decoded %6.1f ns: %+.1f ns = %.2f %% of a 25 us base period; %u MPG counts, "
        "%u errors\n",
        base, config::kPanelInputs + 8 + config::kPanelLights, with_panel, with_panel - base,
        (with_panel - base) / 25'000 * 100,
        [&] {
          drivers::IoFeedback fb;
          b.read_io(fb);
          return fb.panel.counts[0];
        }(),
        b.quadrature_errors(config::PanelCounter::mpg));
    a.disable();
    b.disable();
  }
  fs::remove_all(dir);
  return 0;
}
