#include "cncd/drivers/driver.hpp"

#include <map>

#include "cncd/drivers/gpio_driver.hpp"
#include "cncd/drivers/modbus_driver.hpp"
#include "cncd/drivers/sim_driver.hpp"

namespace cncd::drivers {

std::unique_ptr<Driver> make_driver(const std::string& name, std::string& error) {
  if (name == "sim") return std::make_unique<SimDriver>();
  if (name == "gpio") return std::make_unique<GpioDriver>();
  if (name == "modbus") return std::make_unique<ModbusDriver>();
  error = "unknown driver '" + name + "'";
  return nullptr;
}

std::vector<DriverInstance> make_drivers(const config::MachineConfig& config, std::string& error) {
  std::map<std::string, std::vector<int>> by_name;
  for (std::size_t j = 0; j < config.joints.size(); ++j)
    by_name[config.joints[j].driver].push_back(static_cast<int>(j));
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
