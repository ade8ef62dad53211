// The machine INIs the I/O and spindle configuration tests load: minimal_ini() with a base
// thread and a VCD chip, and the loaded configuration or its warnings.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/machine_config.hpp"
#include "temp_dir.hpp"

namespace cncd::config::test {

using Kind = SignalAddress::Kind;
using Table = SignalAddress::Table;

class IoConfigTest : public MachineIniTest {
 protected:
  // minimal_ini() with a base thread and a VCD chip: what gpio signals need. What `extra`
  // holds starts at line 43 (kFirst).
  static constexpr int kFirst = 43;
  static std::string gpio_ini(const std::string& extra) {
    return replace_line(minimal_ini(), 4, "SERVO_PERIOD = 1000000\nBASE_PERIOD = 25000") + extra;
  }
  static std::string chip() { return "[GPIO]\nCHIP = vcd:/tmp/cncd-io-test.vcd\n"; }
  MachineConfig loaded(const std::string& ini) {
    const auto result = load(ini);
    EXPECT_TRUE(result.ok()) << ::testing::PrintToString(strings(result.problems));
    return result.ok() ? *result.config : MachineConfig{};
  }
  std::vector<std::string> warnings_of(const std::string& ini) {
    return strings(load(ini).warnings);
  }
};

}  // namespace cncd::config::test
