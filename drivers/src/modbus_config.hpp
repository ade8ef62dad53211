// The modbus driver's settings (not installed): see modbus_config.cpp.
#pragma once

#include <map>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "ini_lookup.hpp"
#include "modbus_bus.hpp"

namespace cncd::drivers {

// [MODBUS_<number>]; problems are recorded in `ini`.
BusSettings read_bus(IniLookup& ini, int number);

// The modbus signals (the panel's too) and the VFD of the config, by bus; "" or the first
// problem, naming the file, line and address.
std::string collect_io(const config::MachineConfig& machine, std::map<int, IoSettings>& by_bus);

}  // namespace cncd::drivers
