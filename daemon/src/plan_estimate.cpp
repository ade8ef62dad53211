#include "plan_estimate.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include "plan_sim.hpp"

namespace cncd::daemon {

void PlanEstimator::start(const std::filesystem::path& program,
                          const interp::InterpOptions& options, const interp::Pose& start) {
  cancel();
  {
    std::lock_guard lock(mutex_);
    estimate_ = PlanEstimate{};
    estimate_.state = PlanEstimate::State::running;
    estimate_.reason = "estimating";
  }
  cancel_.store(false);
  thread_ = std::thread([this, program, options, start] {
    // The servo thread and the control socket come first.
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
    PlanSimOptions sim;
    sim.interp = options;
    sim.start_machine = start;
    sim.measure = false;
    sim.max_wall_s = kMaxWallSeconds;
    sim.max_moves = kMaxMoves;
    sim.cancel = &cancel_;
    PlanSimResult result = simulate_plan(machine_, program, sim);
    PlanEstimate estimate;
    if (result.complete()) {
      estimate.state = PlanEstimate::State::done;
      estimate.estimated_s = result.cycle_time_s;
      estimate.move_start_s =
          std::make_shared<const std::vector<double>>(std::move(result.move_start_s));
      estimate.move_line =
          std::make_shared<const std::vector<std::int32_t>>(std::move(result.move_line));
    } else {
      estimate.state = PlanEstimate::State::failed;
      estimate.reason = result.error ? result.error->to_string() : result.stopped->to_string();
    }
    std::lock_guard lock(mutex_);
    estimate_ = std::move(estimate);
  });
}

void PlanEstimator::cancel() {
  cancel_.store(true);
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  estimate_ = PlanEstimate{};
}

PlanEstimate PlanEstimator::get() const {
  std::lock_guard lock(mutex_);
  return estimate_;
}

}  // namespace cncd::daemon
