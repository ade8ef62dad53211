#include "plan_estimate.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include "cncd/pipeline/plan_sim.hpp"

namespace cncd::daemon {

PlanEstimator::~PlanEstimator() {
  for (auto& run : runs_) {
    run.cancel->store(true);
    run.thread.join();
  }
}

void PlanEstimator::start(const std::filesystem::path& program,
                          const interp::InterpOptions& options, const interp::Pose& start) {
  cancel();
  std::uint64_t generation = 0;
  {
    std::lock_guard lock(mutex_);
    generation = generation_;
    estimate_.state = PlanEstimate::State::running;
    estimate_.reason = "estimating";
  }
  Run run{
      {}, std::make_shared<std::atomic<bool>>(false), std::make_shared<std::atomic<bool>>(false)};
  run.thread = std::thread(
      [this, program, options, start, generation, cancel = run.cancel, finished = run.finished] {
        // The servo thread and the control socket come first.
        setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
        pipeline::PlanSimOptions sim;
        sim.interp = options;
        sim.start_machine = start;
        sim.measure = false;
        sim.max_wall_s = kMaxWallSeconds;
        sim.max_moves = kMaxMoves;
        sim.cancel = cancel.get();
        pipeline::PlanSimResult result = pipeline::simulate_plan(machine_, program, sim);
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
        {
          std::lock_guard lock(mutex_);
          if (generation == generation_) estimate_ = std::move(estimate);
        }
        finished->store(true);
      });
  runs_.push_back(std::move(run));
}

void PlanEstimator::cancel() {
  for (auto& run : runs_)
    run.cancel->store(true);
  {
    std::lock_guard lock(mutex_);
    ++generation_;
    estimate_ = PlanEstimate{};
  }
  reap();
}

void PlanEstimator::reap() {
  std::erase_if(runs_, [](Run& run) {
    if (!run.finished->load()) return false;
    run.thread.join();  // past its last step: returns at once
    return true;
  });
}

PlanEstimate PlanEstimator::get() const {
  std::lock_guard lock(mutex_);
  return estimate_;
}

}  // namespace cncd::daemon
