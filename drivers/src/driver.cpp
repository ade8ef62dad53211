#include "cncd/drivers/driver.hpp"

#include <map>

#include "cncd/drivers/evdev_driver.hpp"
#include "cncd/drivers/gpio_driver.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "panel_wiring.hpp"

namespace cncd::drivers {

std::unique_ptr<Driver> make_driver(const std::string& name, std::string& error) {
  if (name == "sim") return std::make_unique<SimDriver>();
  if (name == "gpio") return std::make_unique<GpioDriver>();
  if (name == "modbus") return std::make_unique<ModbusDriver>();
  if (name == "evdev") return std::make_unique<EvdevDriver>();
  error = "unknown driver '" + name + "'";
  return nullptr;
}

std::vector<const char*> io_driver_names(const config::MachineConfig& config) {
  using Kind = config::SignalAddress::Kind;
  bool sim = false, gpio = false, modbus = false;
  const auto note = [&](const config::SignalAddress& a) {
    sim |= a.kind == Kind::sim;
    gpio |= a.kind == Kind::gpio;
    modbus |= a.kind == Kind::modbus;
  };
  const config::SpindleConfig& spindle = config.spindle;
  if (spindle.present) {
    sim |= spindle.driver == config::SpindleDriver::sim;
    gpio |= spindle.driver == config::SpindleDriver::gpio;
    modbus |= spindle.driver == config::SpindleDriver::modbus;
  }
  const config::IoConfig& io = config.io;
  note(io.flood);
  note(io.mist);
  for (const auto& a : io.digital_outputs)
    note(a);
  for (const auto& a : io.analog_outputs)
    note(a);
  for (const auto& a : io.digital_inputs)
    note(a);
  for (const auto& a : io.analog_inputs)
    note(a);
  for_each_panel_address(config.panel, note);
  std::vector<const char*> out;
  if (gpio) out.push_back("gpio");
  if (modbus) out.push_back("modbus");
  if (sim) out.push_back("sim");
  return out;
}

std::vector<DriverInstance> make_drivers(const config::MachineConfig& config, std::string& error) {
  std::map<std::string, std::vector<int>> by_name;
  for (std::size_t j = 0; j < config.joints.size(); ++j)
    by_name[config.joints[j].driver].push_back(static_cast<int>(j));
  // Drivers that only drive the spindle or signals get no joints.
  for (const char* name : io_driver_names(config))
    by_name.try_emplace(name);
  if (uses_evdev(config)) by_name.try_emplace("evdev");
  std::vector<DriverInstance> out;
  for (const auto& [name, joints] : by_name) {
    auto driver = make_driver(name, error);
    if (!driver) return {};
    if (auto problem = driver->configure(config, joints); !problem.empty()) {
      error = "driver '" + name + "': " + problem;
      return {};
    }
    out.push_back(DriverInstance{std::move(driver), joints});
  }
  return out;
}

}  // namespace cncd::drivers
