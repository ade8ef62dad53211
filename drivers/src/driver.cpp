#include "cncd/drivers/driver.hpp"

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

}  // namespace cncd::drivers
