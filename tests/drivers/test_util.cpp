#include "test_util.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

namespace cncd::test {

config::LoadResult load_machine(const TempDir& dir, int joints, const std::string& joint_keys,
                                const std::string& extra, std::int64_t base_period_ns) {
  const std::string letters = std::string(config::kAxisLetters).substr(0, joints);
  std::ostringstream ini;
  ini << "[EMC]\nMACHINE = driver test\n[EMCMOT]\nSERVO_PERIOD = 1000000\n";
  if (base_period_ns > 0) ini << "BASE_PERIOD = " << base_period_ns << "\n";
  ini << "[TRAJ]\nCOORDINATES = " << letters << "\nLINEAR_UNITS = mm\n";
  ini << "[KINS]\nKINEMATICS = trivkins coordinates=" << letters << "\nJOINTS = " << joints << "\n";
  for (int j = 0; j < joints; ++j) {
    ini << "[AXIS_" << letters[static_cast<std::size_t>(j)] << "]\nMIN_LIMIT = -100\n"
        << "MAX_LIMIT = 100\nMAX_VELOCITY = 50\nMAX_ACCELERATION = 500\n";
    ini << "[JOINT_" << j << "]\nMIN_LIMIT = -100\nMAX_LIMIT = 100\nMAX_VELOCITY = 50\n"
        << "MAX_ACCELERATION = 500\nFERROR = 5\nMIN_FERROR = 1\n";
    std::string keys = joint_keys;
    for (std::size_t at = keys.find("{j}"); at != std::string::npos; at = keys.find("{j}"))
      keys.replace(at, 3, std::to_string(j));
    ini << keys << "\n";
  }
  ini << extra << "\n";
  auto result = config::load_machine_config(dir.write("machine.ini", ini.str()));
  for (const auto& p : result.problems)
    ADD_FAILURE() << p.to_string();
  return result;
}

std::vector<VcdChange> read_vcd(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::map<std::string, std::string> names;
  std::vector<VcdChange> changes;
  std::int64_t now = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("$var", 0) == 0) {
      std::istringstream words(line);
      std::string var, type, width, id, name;
      words >> var >> type >> width >> id >> name;
      names[id] = name;
    } else if (!line.empty() && line[0] == '#') {
      now = std::stoll(line.substr(1));
    } else if (!line.empty() && (line[0] == '0' || line[0] == '1')) {
      changes.push_back(VcdChange{now, names[line.substr(1)], line[0] - '0'});
    }
  }
  return changes;
}

StepStats step_stats(const std::vector<VcdChange>& changes, int joint) {
  const std::string step = "j" + std::to_string(joint) + "_step";
  const std::string dir = "j" + std::to_string(joint) + "_dir";
  StepStats s;
  int step_level = 0;
  int dir_level = 0;
  std::int64_t last_rise = -1, last_fall = -1, last_dir_change = -1;
  for (const auto& c : changes) {
    if (c.signal == step && c.level != step_level) {
      step_level = c.level;
      if (c.level == 1) {
        ++s.rising_edges;
        s.net_steps += dir_level != 0 ? -1 : 1;
        if (last_fall >= 0) s.min_low_ns = std::min(s.min_low_ns, c.time_ns - last_fall);
        if (last_dir_change >= 0) {
          s.min_dir_setup_ns = std::min(s.min_dir_setup_ns, c.time_ns - last_dir_change);
          last_dir_change = -1;
        }
        last_rise = c.time_ns;
      } else {
        s.min_high_ns = std::min(s.min_high_ns, c.time_ns - last_rise);
        last_fall = c.time_ns;
      }
    } else if (c.signal == dir && c.level != dir_level) {
      dir_level = c.level;
      ++s.direction_changes;
      if (step_level == 1) s.min_dir_hold_ns = -1;
      if (last_fall >= 0) s.min_dir_hold_ns = std::min(s.min_dir_hold_ns, c.time_ns - last_fall);
      last_dir_change = c.time_ns;
    }
  }
  return s;
}

bool realtime_scheduling_permitted() {
  // Asked on a thread of its own, which ends with its priority.
  bool permitted = false;
  std::thread probe([&permitted] {
    sched_param param{};
    param.sched_priority = sched_get_priority_min(SCHED_FIFO);
    permitted = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  });
  probe.join();
  return permitted;
}

}  // namespace cncd::test
