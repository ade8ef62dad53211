// Driver figures on this machine: Modbus update rate achieved against the configured one on
// loopback, and the step/dir base thread's step rate and timing error with the VCD backend.
// Prints figures only; timing never fails anything.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/drive_sim.hpp"
#include "cncd/drivers/gpio_driver.hpp"
#include "cncd/drivers/modbus_driver.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cncd;

std::string machine(int joints, const std::string& joint_keys, const std::string& extra,
                    long base_period_ns) {
  const std::string letters = std::string(config::kAxisLetters).substr(0, joints);
  std::ostringstream ini;
  ini << "[EMCMOT]\nSERVO_PERIOD = 1000000\n";
  if (base_period_ns > 0) ini << "BASE_PERIOD = " << base_period_ns << "\n";
  ini << "[TRAJ]\nCOORDINATES = " << letters
      << "\n[KINS]\nKINEMATICS = trivkins\nJOINTS = " << joints << "\n";
  for (int j = 0; j < joints; ++j) {
    std::string keys = joint_keys;
    for (auto at = keys.find("{j}"); at != std::string::npos; at = keys.find("{j}"))
      keys.replace(at, 3, std::to_string(j));
    ini << "[AXIS_" << letters[static_cast<std::size_t>(j)] << "]\n[JOINT_" << j << "]\n" << keys;
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

void modbus_rate(const fs::path& dir, int period_ms) {
  drivers::DriveSimOptions options;
  options.drives = 3;
  options.first_slave = 10;
  drivers::DriveSim sim(options);
  if (const auto e = sim.start(); !e.empty()) {
    std::printf("modbus: %s\n", e.c_str());
    return;
  }
  const auto cfg =
      load(dir, machine(3, "DRIVER = modbus\nMODBUS = 0\nSLAVE = 1{j}\nSCALE = 1000\n",
                        "[MODBUS_0]\nHOST = 127.0.0.1\nPORT = " + std::to_string(sim.port()) +
                            "\nUPDATE_PERIOD_MS = " + std::to_string(period_ms) + "\n",
                        0));
  drivers::ModbusDriver driver;
  if (const auto e = driver.configure(cfg, {0, 1, 2}); !e.empty()) {
    std::printf("modbus: %s\n", e.c_str());
    return;
  }
  driver.enable();
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t first = driver.bus_cycles(0);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const std::uint64_t cycles = driver.bus_cycles(0) - first;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  driver.disable();
  const double rate = static_cast<double>(cycles) / seconds;
  std::printf(
      "modbus tcp loopback, 3 drives: configured %d ms (%.1f Hz), achieved %.1f Hz "
      "(%.3f ms per update)\n",
      period_ms, 1000.0 / period_ms, rate, 1000.0 / rate);
}

void gpio_rate(const fs::path& dir, long base_ns) {
  const std::string vcd = (dir / "bench.vcd").string();
  const auto cfg = load(dir, machine(1,
                                     "DRIVER = gpio\nSCALE = 1000\nSTEP_LINE = 0\nDIR_LINE = 1\n"
                                     "STEPLEN = 1\nSTEPSPACE = 1\n",
                                     "[GPIO]\nCHIP = vcd:" + vcd + "\n", base_ns));
  drivers::GpioDriver driver;
  driver.pace_recording_in_real_time(true);  // a wake-up every base period, as for pins
  if (const auto e = driver.configure(cfg, {0}); !e.empty()) {
    std::printf("gpio: %s\n", e.c_str());
    return;
  }
  driver.enable();
  // Command a velocity near the step timing limit: 1 step per 2 base periods.
  const double steps_per_s = 1e9 / (2.0 * static_cast<double>(base_ns)) * 0.9;
  const double velocity = steps_per_s / 1000.0;
  double position = 0;
  auto next = std::chrono::steady_clock::now();
  const auto start = next;
  for (int i = 0; i < 2000; ++i) {
    position += velocity * 1e-3;
    drivers::JointCommand c{position, velocity, true};
    driver.write(&c, 1);
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto stats = driver.base_stats();
  const auto steps = driver.step_count(0);
  driver.disable();
  // Pulse widths as recorded (time stamps of the bulk writes).
  std::ifstream in(vcd);
  std::string line;
  long long now = 0, rise = -1, min_high = 1LL << 62, max_high = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') now = std::stoll(line.substr(1));
    if (line == "1!") rise = now;
    if (line == "0!" && rise >= 0) {
      min_high = std::min(min_high, now - rise);
      max_high = std::max(max_high, now - rise);
    }
  }
  std::printf(
      "gpio base thread %ld ns (vcd): %.0f steps/s (commanded %.0f), %llu periods, "
      "wake late mean %.0f ns max %lld ns; step high %lld .. %lld ns (nominal %ld)\n",
      base_ns, static_cast<double>(steps) / seconds, steps_per_s,
      static_cast<unsigned long long>(stats.periods), stats.mean_late_ns,
      static_cast<long long>(stats.max_late_ns), min_high, max_high, base_ns);
}

}  // namespace

int main() {
  std::string pattern = (fs::temp_directory_path() / "cncd-bench-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) return 1;
  const fs::path dir = pattern;
  modbus_rate(dir, 2);
  modbus_rate(dir, 10);
  gpio_rate(dir, 25'000);
  gpio_rate(dir, 50'000);
  fs::remove_all(dir);
  return 0;
}
