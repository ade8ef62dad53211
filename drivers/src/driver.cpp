#include "cncd/drivers/driver.hpp"

#include "cncd/drivers/sim_driver.hpp"

namespace cncd::drivers {

std::unique_ptr<Driver> make_driver(const std::string& name, std::string& error) {
  if (name == "sim") return std::make_unique<SimDriver>();
  if (name == "gpio" || name == "modbus") {
    error = "driver '" + name + "' is not available in this build";
  } else {
    error = "unknown driver '" + name + "'";
  }
  return nullptr;
}

}  // namespace cncd::drivers
