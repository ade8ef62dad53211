// Spindle and output figures on this machine: what write_io + read_io (a spindle and 8 digital
// outputs) add to a servo period, against the same driver's joint write + read (3 joints),
// and the duty error of the GPIO spindle PWM at a 10 kHz base rate, measured on the recorded
// edges. Prints figures only; timing never fails anything.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/drive_sim.hpp"
#include "cncd/drivers/gpio_driver.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "cncd/motion/servo_loop.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cncd;
using Clock = std::chrono::steady_clock;

std::string machine(const std::string& joint_keys, const std::string& extra, long base_ns) {
  std::ostringstream ini;
  ini << "[EMCMOT]\nSERVO_PERIOD = 1000000\n";
  if (base_ns > 0) ini << "BASE_PERIOD = " << base_ns << "\n";
  ini << "[TRAJ]\nCOORDINATES = XYZ\n[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n";
  for (int j = 0; j < 3; ++j) {
    std::string keys = joint_keys;
    for (auto at = keys.find("{j}"); at != std::string::npos; at = keys.find("{j}"))
      keys.replace(at, 3, std::to_string(j));
    ini << "[AXIS_"
        << "XYZ"[j] << "]\n[JOINT_" << j << "]\n"
        << keys;
  }
  return ini.str() + extra;
}

config::MachineConfig load(const fs::path& dir, const std::string& text) {
  std::ofstream(dir / "bench.ini") << text;
  auto result = config::load_machine_config(dir / "bench.ini");
  if (!result.ok()) {
    for (const auto& p : result.problems)
      std::fprintf(stderr, "%s\n", p.to_string().c_str());
    std::exit(1);
  }
  return *result.config;
}

config::SignalAddress address(config::SignalAddress::Kind kind, int n) {
  config::SignalAddress a;
  a.kind = kind;
  a.line = std::to_string(n);
  a.name = "out" + std::to_string(n);
  a.slave = 20;
  a.address = 100 + n;
  a.text = "bench " + std::to_string(n);
  return a;
}

// A spindle on `driver` and DIGITAL_OUTPUT_0..7 on addresses of `kind` from line `first`.
void add_io(config::MachineConfig& c, config::SpindleDriver driver,
            config::SignalAddress::Kind kind, int first) {
  c.spindle.present = true;
  c.spindle.driver = driver;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.acceleration = 10000;
  c.spindle.modbus = 0;
  c.spindle.slave = 20;
  c.spindle.speed_scale = 0.1;
  c.spindle.command_register = 50;  // clear of the simulated joint drives' registers
  c.spindle.speed_register = 51;
  c.spindle.actual_speed_register = 50;
  c.spindle.status_register = 51;
  if (kind == config::SignalAddress::Kind::gpio) {
    c.spindle.enable = address(kind, first + 8);
    c.spindle.direction = address(kind, first + 9);
    c.spindle.pwm = address(kind, first + 10);
  }
  for (int n = 0; n < 8; ++n)
    c.io.digital_outputs[static_cast<std::size_t>(n)] = address(kind, first + n);
}

// Mean ns per servo period of joint write + read, and of write_io + read_io, interleaved so
// both see the same caches and clock.
void cost(const char* name, drivers::Driver& driver) {
  constexpr int kPeriods = 200'000;
  drivers::JointCommand commands[3];
  drivers::JointFeedback feedback[3];
  drivers::IoCommand io;
  io.spindle = drivers::SpindleCommand{true, false, 12000};
  drivers::IoFeedback io_feedback;
  std::int64_t joint_ns = 0;
  std::int64_t io_ns = 0;
  for (int i = 0; i < kPeriods; ++i) {
    for (int j = 0; j < 3; ++j)
      commands[j] = drivers::JointCommand{i * 1e-4, 0.1, true, static_cast<std::uint64_t>(i + 1)};
    io.digital = static_cast<std::uint32_t>(i) & 0xffu;
    const auto t0 = Clock::now();
    driver.write(commands, 3);
    driver.read(feedback, 3);
    const auto t1 = Clock::now();
    driver.write_io(io);
    driver.read_io(io_feedback);
    const auto t2 = Clock::now();
    joint_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
    io_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count();
  }
  const double joint = static_cast<double>(joint_ns) / kPeriods;
  const double added = static_cast<double>(io_ns) / kPeriods;
  std::printf(
      "%-6s joints (3) write+read %7.1f ns; write_io+read_io (spindle, 8 outputs) %7.1f ns = "
      "%.2f x the joints, %.4f %% of a 1 ms period\n",
      name, joint, added, added / joint, added / 1e6 * 100);
}

void costs(const fs::path& dir) {
  using Kind = config::SignalAddress::Kind;
  {
    auto c = load(dir, machine("DRIVER = sim\n", "", 0));
    add_io(c, config::SpindleDriver::sim, Kind::sim, 0);
    drivers::SimDriver d;
    if (const auto e = d.configure(c, {0, 1, 2}); !e.empty()) std::printf("sim: %s\n", e.c_str());
    cost("sim", d);
  }
  {
    auto c = load(dir, machine("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = 2{j}\nDIR_LINE = 3{j}\n",
                               "[GPIO]\nCHIP = vcd:" + (dir / "cost.vcd").string() + "\n", 25'000));
    add_io(c, config::SpindleDriver::gpio, Kind::gpio, 0);
    drivers::GpioDriver d;
    d.use_manual_clock(true);  // the servo side alone: no base thread competing for the CPU
    if (const auto e = d.configure(c, {0, 1, 2}); !e.empty()) std::printf("gpio: %s\n", e.c_str());
    cost("gpio", d);
  }
  {
    drivers::DriveSimOptions options;
    options.drives = 3;
    options.first_slave = 10;
    drivers::DriveSim sim(options);
    if (const auto e = sim.start(); !e.empty()) {
      std::printf("modbus: %s\n", e.c_str());
      return;
    }
    auto c =
        load(dir, machine("DRIVER = modbus\nMODBUS = 0\nSLAVE = 1{j}\nSCALE = 1000\n",
                          "[MODBUS_0]\nHOST = 127.0.0.1\nPORT = " + std::to_string(sim.port()) +
                              "\nUPDATE_PERIOD_MS = 2\n",
                          0));
    add_io(c, config::SpindleDriver::modbus, Kind::modbus, 0);
    drivers::ModbusDriver d;
    if (const auto e = d.configure(c, {0, 1, 2}); !e.empty()) {
      std::printf("modbus: %s\n", e.c_str());
      return;
    }
    d.enable();
    cost("modbus", d);
    d.disable();
  }
}

// Duty of the recorded spindle_pwm line at `duty` commanded, PWM at `frequency` Hz, base
// thread at 10 kHz in virtual time: the mean over 1 s and the worst single cycle.
void pwm_error(const fs::path& dir, double frequency, double duty) {
  constexpr long kBaseNs = 100'000;
  const fs::path vcd = dir / "pwm.vcd";
  auto c = load(dir, machine("DRIVER = gpio\nSCALE = 100\nSTEP_LINE = 2{j}\nDIR_LINE = 3{j}\n",
                             "[GPIO]\nCHIP = vcd:" + vcd.string() + "\n", kBaseNs));
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::gpio;
  c.spindle.max_forward_velocity = 24000;
  c.spindle.pwm.kind = config::SignalAddress::Kind::gpio;
  c.spindle.pwm.line = "5";
  c.spindle.pwm_frequency = frequency;
  drivers::GpioDriver d;
  d.use_manual_clock(true);
  if (const auto e = d.configure(c, {0, 1, 2}); !e.empty()) {
    std::printf("pwm: %s\n", e.c_str());
    return;
  }
  d.enable();
  drivers::IoCommand io;
  io.spindle = drivers::SpindleCommand{true, false, duty * 24000};
  d.write_io(io);
  std::int64_t now = 0;
  for (int i = 0; i < 10'000 + 1; ++i)  // 1 s and one period
    d.run_base_period(now += kBaseNs);
  d.disable();
  // Rising edges and the high time after each, from the file.
  std::ifstream in(vcd);
  std::string line, id;
  std::int64_t t = 0;
  std::vector<std::int64_t> rises, falls;
  while (std::getline(in, line)) {
    if (line.rfind("$var", 0) == 0 && line.find(" spindle_pwm ") != std::string::npos) {
      std::istringstream words(line);
      std::string var, type, width;
      words >> var >> type >> width >> id;
    } else if (!line.empty() && line[0] == '#') {
      t = std::stoll(line.substr(1));
    } else if (!id.empty() && line.size() > 1 && line.substr(1) == id) {
      (line[0] == '1' ? rises : falls).push_back(t);
    }
  }
  double worst = 0;
  std::int64_t high = 0;
  std::size_t cycles = 0;
  for (std::size_t k = 0; k + 1 < rises.size(); ++k) {
    const auto fall = std::upper_bound(falls.begin(), falls.end(), rises[k]);
    const std::int64_t on =
        (fall != falls.end() && *fall < rises[k + 1] ? *fall : rises[k + 1]) - rises[k];
    const double cycle_duty =
        static_cast<double>(on) / static_cast<double>(rises[k + 1] - rises[k]);
    worst = std::max(worst, std::abs(cycle_duty - duty));
    high += on;
    ++cycles;
  }
  if (cycles == 0) {
    std::printf("pwm %5.0f Hz duty %.3f: no cycles recorded\n", frequency, duty);
    return;
  }
  const double mean = static_cast<double>(high) / static_cast<double>(rises.back() - rises.front());
  std::printf(
      "pwm %5.0f Hz (%5.1f base periods a cycle) duty %.3f: measured %.5f over %zu cycles, "
      "error %+.5f; worst single cycle %.3f off\n",
      frequency, 1e9 / kBaseNs / frequency, duty, mean, cycles, mean - duty, worst);
}

}  // namespace

// The whole servo period, ServoLoop::cycle() on the simulated driver with the machine on: a
// machine with a turning sim spindle and 8 sim outputs toggling against the same machine with
// neither, interleaved. What the spindle and outputs add in all, servo loop and driver.
void servo_cost(const fs::path& dir) {
  constexpr int kPeriods = 200'000;
  const auto plain = load(dir, machine("DRIVER = sim\n", "", 0));
  auto with_io = plain;
  add_io(with_io, config::SpindleDriver::sim, config::SignalAddress::Kind::sim, 0);
  struct Machine {
    drivers::SimDriver driver;
    std::unique_ptr<motion::ServoLoop> loop;
  };
  const auto make = [](const config::MachineConfig& c, Machine& m) {
    if (const auto e = m.driver.configure(c, {0, 1, 2}); !e.empty())
      std::printf("servo: %s\n", e.c_str());
    m.loop = std::make_unique<motion::ServoLoop>(
        c, std::vector<motion::DriverBinding>{{&m.driver, {0, 1, 2}}});
    for (const auto kind : {motion::Command::Kind::reset_estop, motion::Command::Kind::on}) {
      motion::Command command;
      command.kind = kind;
      m.loop->commands().push(command);
      m.loop->cycle(0);
    }
  };
  Machine a, b;
  make(plain, a);
  make(with_io, b);
  // Spindle on and the 8 outputs set, as actions on the path.
  motion::Segment spin;
  spin.kind = motion::Segment::Kind::dwell;
  spin.action.kind = motion::IoAction::Kind::spindle;
  spin.action.direction = 1;
  spin.action.rpm = 12000;
  b.loop->segments().push(spin);
  for (int n = 0; n < 8; ++n) {
    motion::Segment out = spin;
    out.action.kind = motion::IoAction::Kind::digital_output;
    out.action.index = static_cast<std::int16_t>(n);
    out.action.on = true;
    b.loop->segments().push(out);
  }
  std::int64_t plain_ns = 0, io_ns = 0;
  for (int i = 0; i < kPeriods; ++i) {
    const auto t0 = Clock::now();
    a.loop->cycle(0);
    const auto t1 = Clock::now();
    b.loop->cycle(0);
    const auto t2 = Clock::now();
    plain_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
    io_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count();
  }
  const auto s = b.loop->status();
  const double base = static_cast<double>(plain_ns) / kPeriods;
  const double with = static_cast<double>(io_ns) / kPeriods;
  std::printf(
      "servo period (sim, 3 joints): %7.1f ns; with a spindle at %.0f rpm and %d outputs on "
      "%7.1f ns: %+.1f ns = %.4f %% of a 1 ms period\n",
      base, s.spindle.actual_rpm, __builtin_popcount(s.io.douts), with, with - base,
      (with - base) / 1e6 * 100);
}

int main() {
  std::string pattern = (fs::temp_directory_path() / "cncd-io-bench-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) return 1;
  const fs::path dir = pattern;
  costs(dir);
  servo_cost(dir);
  for (const double frequency : {1000.0, 300.0}) {
    for (const double duty : {0.05, 0.25, 1.0 / 3.0, 0.5, 0.9})
      pwm_error(dir, frequency, duty);
  }
  fs::remove_all(dir);
  return 0;
}
