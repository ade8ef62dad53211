// A fresh directory per test for INI fixtures, removed afterwards.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
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

// A minimal valid machine; tests append or replace sections to break it.
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

}  // namespace cncd::config::test
