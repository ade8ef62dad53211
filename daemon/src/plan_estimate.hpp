// The running time of the open program, estimated in the background with the plan simulation
// (plan_sim) so that program.open answers at once and the control socket stays responsive.
// start()/cancel()/get() are called on the daemon's main loop thread; the simulation runs on
// a thread of its own, at a lower CPU priority, within a time and a move budget.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"

namespace cncd::daemon {

struct PlanEstimate {
  enum class State { none, running, done, failed };
  State state = State::none;
  double estimated_s = 0;  // the whole program, when done
  // When each move of a run from the top starts (s), in queue order, when done.
  std::shared_ptr<const std::vector<double>> move_start_s;
  std::shared_ptr<const std::vector<std::int32_t>> move_line;  // each move's source line
  std::string reason;  // why there is no estimate (running, failed)
};

class PlanEstimator {
 public:
  // The simulation stops (no estimate, with the reason) past these.
  static constexpr double kMaxWallSeconds = 30;
  static constexpr std::size_t kMaxMoves = 4'000'000;

  explicit PlanEstimator(const config::MachineConfig& machine) : machine_(machine) {}
  ~PlanEstimator() { cancel(); }
  PlanEstimator(const PlanEstimator&) = delete;
  PlanEstimator& operator=(const PlanEstimator&) = delete;

  // Cancels any estimate under way and starts one for `program` run from machine position
  // `start` (machine coordinates and units).
  void start(const std::filesystem::path& program, const interp::InterpOptions& options,
             const interp::Pose& start);
  // Stops the estimate under way (waits for its thread) and forgets the last one.
  void cancel();
  PlanEstimate get() const;

 private:
  const config::MachineConfig& machine_;
  std::thread thread_;
  std::atomic<bool> cancel_{false};
  mutable std::mutex mutex_;
  PlanEstimate estimate_;  // guarded by mutex_
};

}  // namespace cncd::daemon
