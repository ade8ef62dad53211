// A fresh directory per test for INI fixtures, removed afterwards.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::config::test {

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device random;
    dir_ = std::filesystem::temp_directory_path() /
           ("cncd-config-test-" + std::to_string(random()) + "-" + std::to_string(random()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::filesystem::path write(const std::string& name, const std::string& content) {
    const auto path = dir_ / name;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }
  // "FILE:LINE" of a fixture file, as problems print it.
  std::string at(const std::string& name, int line) const {
    return (dir_ / name).lexically_normal().string() + ":" + std::to_string(line);
  }

  std::filesystem::path dir_;
};

inline std::vector<std::string> strings(const std::vector<Problem>& problems) {
  std::vector<std::string> out;
  for (const auto& p : problems)
    out.push_back(p.to_string());
  return out;
}

inline bool any_contains(const std::vector<Problem>& problems, const std::string& text) {
  return std::any_of(problems.begin(), problems.end(), [&](const Problem& p) {
    return p.to_string().find(text) != std::string::npos;
  });
}

// The environment the loader sees in tests that set LoadOptions::getenv to fake_getenv.
inline std::map<std::string, std::string>& fake_env() {
  static std::map<std::string, std::string> env;
  return env;
}

inline const char* fake_getenv(const char* name) {
  const auto it = fake_env().find(name);
  return it == fake_env().end() ? nullptr : it->second.c_str();
}

// The INI text with its line `line` (1-based) replaced by `text`.
inline std::string replace_line(std::string ini, int line, const std::string& text) {
  std::size_t start = 0;
  for (int i = 1; i < line; ++i)
    start = ini.find('\n', start) + 1;
  const std::size_t end = ini.find('\n', start);
  return ini.replace(start, end - start, text);
}

// A minimal valid machine; tests append or replace sections to break it. Its line numbers:
// [EMCMOT] SERVO_PERIOD 4, [TRAJ] COORDINATES 6, LINEAR_UNITS 7, ANGULAR_UNITS 8, [KINS] 9,
// KINEMATICS 10, JOINTS 11, [AXIS_X] 12 (MIN_LIMIT 13, MAX_LIMIT 14, MAX_VELOCITY 15,
// MAX_ACCELERATION 16), [AXIS_Y] 17, [AXIS_Z] 22, [JOINT_0] 27 (MIN_LIMIT 28, MAX_LIMIT 29,
// MAX_VELOCITY 30, MAX_ACCELERATION 31), [JOINT_1] 32, [JOINT_2] 37 .. 41.
inline std::string minimal_ini(const std::string& extra_joint_keys = "") {
  std::string ini =
      "[EMC]\nMACHINE = test\n"
      "[EMCMOT]\nSERVO_PERIOD = 1000000\n"
      "[TRAJ]\nCOORDINATES = X Y Z\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n"
      "[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n";
  for (const char axis : std::string("XYZ")) {
    ini += std::string("[AXIS_") + axis +
           "]\nMIN_LIMIT = -10\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n";
  }
  for (int j = 0; j < 3; ++j) {
    ini += "[JOINT_" + std::to_string(j) +
           "]\nMIN_LIMIT = -10\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n" +
           extra_joint_keys;
  }
  return ini;
}

// Tests of one machine INI file, m.ini, whose problems are reported at its lines.
class MachineIniTest : public TempDirTest {
 protected:
  LoadResult load(const std::string& ini) { return load_machine_config(write("m.ini", ini)); }
  // The problems of an INI that must fail to load.
  std::vector<std::string> problems_of(const std::string& ini) {
    const auto result = load(ini);
    EXPECT_FALSE(result.ok());
    EXPECT_EQ(result.config.has_value(), result.problems.empty());
    return strings(result.problems);
  }
  std::string at(int line) const { return TempDirTest::at("m.ini", line); }
  // The problems of minimal_ini() with its line `line` replaced by `text`.
  std::vector<std::string> problems_with(int line, const std::string& text) {
    return problems_of(replace_line(minimal_ini(), line, text));
  }
  // One problem, reported at line `line` of m.ini.
  std::vector<std::string> problem_at(int line, const std::string& message) const {
    return {at(line) + ": " + message};
  }
};

}  // namespace cncd::config::test
