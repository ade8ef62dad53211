// The task's side of the job history: a row as a program run starts and as it ends, and the
// history's answers and reports passed on.
#include <chrono>

#include "task.hpp"

namespace cncd::daemon {
namespace {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

void Task::begin_job() {
  if (jobs_ == nullptr) return;
  JobRecord job;
  job.program = program_path_;
  job.started = unix_now();
  job.started_by = events_.actor();
  job.from_line = run_from_line_;
  job.estimate_s = whole_estimate();
  job_ = jobs_->begin(std::move(job));
}

// The estimate is of the whole program: a run from a line has none to compare with.
std::optional<double> Task::whole_estimate() const {
  const PlanEstimate estimate = estimator_.get();
  if (!from_top_ || estimate.state != PlanEstimate::State::done) return std::nullopt;
  return estimate.estimated_s;
}

void Task::end_job(const std::string& result, const std::string& error, int line) {
  if (jobs_ == nullptr || job_ == 0) return;
  JobRecord job;
  job.ended = unix_now();
  job.result = result;
  job.error = error;
  job.error_line = result == "done" ? 0 : line;
  job.cycle_s = motion_s_;
  // Worked out in the background: it may have come during the run.
  job.estimate_s = whole_estimate();
  using enum config::TelemetryConfig::PartCount;
  const int end = runner_->end_code();
  const auto counting = config_.telemetry.part_count;
  job.parts = result == "done" && ((counting == m30 && end == 30) ||
                                   (counting == m2 && (end == 2 || end == 30)))
                  ? 1
                  : 0;
  jobs_->end(job_, job);
  job_ = 0;
}

void Task::ask_jobs(std::uint64_t token, bool stats, double since, int limit) {
  if (jobs_ == nullptr) {
    throw TaskError(TaskErrorKind::unavailable, "this daemon keeps no job history");
  }
  if (stats) {
    jobs_->ask_stats(token, since);
  } else {
    jobs_->ask_history(token, since, limit);
  }
}

void Task::poll_jobs() {
  if (jobs_ == nullptr) return;
  for (auto& [token, outcome] : jobs_->take())
    answers_.post(token, std::move(outcome));
  for (auto& [level, message] : jobs_->take_reports())
    events_.add(level, "jobs", std::move(message));
}

}  // namespace cncd::daemon
