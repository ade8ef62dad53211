// cncd-check on programs written to a temporary directory, with or without a copy of the
// example machine (sim_mm.ini: mm, no offsets in its parameter file).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "daemon_process.hpp"

namespace cncd::test {

class CncdCheck : public ::testing::Test {
 protected:
  void SetUp() override { ini_ = copy_example_machine(dir_.path()); }

  // cncd-check `args` on `program` (written as prog.ngc).
  CommandResult check(const std::string& program, std::vector<std::string> args = {}) {
    const auto path = dir_.write("prog.ngc", program);
    std::vector<std::string> argv{CNCD_CHECK_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.push_back(path.string());
    return run_command(argv);
  }

  // The example machine with `keys` added to its [RS274NGC] section.
  std::string machine_with(const std::string& keys) {
    std::string text = slurp(ini_);
    const std::string section = "[RS274NGC]\n";
    const auto at = text.find(section);
    EXPECT_NE(at, std::string::npos);
    if (at != std::string::npos) text.insert(at + section.size(), keys);
    return dir_.write("machine.ini", text).string();
  }

  TempDir dir_;
  std::filesystem::path ini_;
};

}  // namespace cncd::test
