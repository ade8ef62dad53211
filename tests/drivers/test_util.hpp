// Shared helpers of the driver tests: temporary machines and a reader for value change dumps.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "daemon_process.hpp"

namespace cncd::test {

// A small machine: servo 1 ms, `joints` linear joints (XYZ...), each with `joint_keys` added,
// plus `extra` sections. Returns the loaded config or fails the test with the problems.
config::LoadResult load_machine(const TempDir& dir, int joints, const std::string& joint_keys,
                                const std::string& extra, std::int64_t base_period_ns = 0);

struct VcdChange {
  std::int64_t time_ns;
  std::string signal;
  int level;
};

// Every value change of a VCD file in order (the initial $dumpvars values at time 0 included).
std::vector<VcdChange> read_vcd(const std::filesystem::path& path);

struct StepStats {
  std::int64_t net_steps = 0;  // rising edges, signed by the direction line
  std::int64_t min_high_ns = INT64_MAX;
  std::int64_t min_low_ns = INT64_MAX;
  std::int64_t min_dir_setup_ns = INT64_MAX;  // direction change to next rising step edge
  std::int64_t min_dir_hold_ns = INT64_MAX;   // falling step edge to next direction change
  std::int64_t rising_edges = 0;
  std::int64_t direction_changes = 0;
};

// Whether this process may run a thread at SCHED_FIFO, as cncd's servo and bus threads ask
// to: root, CAP_SYS_NICE or an RLIMIT_RTPRIO (LinuxCNC's installs grant one to its users).
bool realtime_scheduling_permitted();
// Why a test of a real-time deadline is skipped without it.
inline constexpr const char* kNoRealtime =
    "needs real-time scheduling (SCHED_FIFO: CAP_SYS_NICE or an rtprio limit): without it a "
    "loaded machine delays cncd's threads past the deadline judged";

// Step timing of joint `joint` ("j<joint>_step", "j<joint>_dir") in a recording.
StepStats step_stats(const std::vector<VcdChange>& changes, int joint);

}  // namespace cncd::test
