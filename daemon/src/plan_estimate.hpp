// The running time of the open program, estimated in the background with the plan simulation
// (plan_sim) so that program.open answers at once and the control socket stays responsive.
// start()/cancel()/get() are called on the daemon's main loop thread and never wait for a
// simulation; each runs on a thread of its own, at a lower CPU priority, within a time and a
// move budget.
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
  // Waits for the simulations still winding down.
  ~PlanEstimator();
  PlanEstimator(const PlanEstimator&) = delete;
  PlanEstimator& operator=(const PlanEstimator&) = delete;

  // Cancels any estimate under way and starts one for `program` run from machine position
  // `start` (machine coordinates and units). Never waits for the cancelled one to end.
  void start(const std::filesystem::path& program, const interp::InterpOptions& options,
             const interp::Pose& start);
  // Cancels the estimate under way, if any, and forgets the last one; never waits.
  void cancel();
  PlanEstimate get() const;

 private:
  struct Run {
    std::thread thread;
    std::shared_ptr<std::atomic<bool>> cancel;
    std::shared_ptr<std::atomic<bool>> finished;
  };
  // Joins the cancelled runs that have ended.
  void reap();

  const config::MachineConfig& machine_;
  std::vector<Run> runs_;  // the current one last; used on the caller's thread only
  mutable std::mutex mutex_;
  std::uint64_t generation_ = 0;  // guarded by mutex_: the run whose result is wanted
  PlanEstimate estimate_;         // guarded by mutex_
};

}  // namespace cncd::daemon
