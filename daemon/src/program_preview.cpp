#include "program_preview.hpp"

#include <algorithm>

#include "cncd/pipeline/program_preview.hpp"

namespace cncd::daemon {

ProgramPreviewer::ProgramPreviewer(const config::MachineConfig& machine) : machine_(machine) {
  // The servo thread, the control socket and program.open's check come first.
  worker_.start(
      15, [this] { return !jobs_.empty(); }, [this](WorkerThread::Lock& lock) { work(lock); });
}

ProgramPreviewer::~ProgramPreviewer() {
  worker_.stop([this] {
    jobs_.clear();
    cancel_.store(true);
  });
}

void ProgramPreviewer::open(const std::filesystem::path& program,
                            const interp::InterpOptions& options, const interp::Pose& start) {
  for (auto& [tolerance, tokens] : waiting_) {
    for (const auto token : tokens) {
      ready_.emplace_back(token,
                          TaskError(TaskErrorKind::cancelled,
                                    "program.preview cancelled: another program was opened"));
    }
  }
  waiting_.clear();
  cached_.clear();
  has_program_ = true;
  {
    std::lock_guard lock(worker_.mutex());
    ++generation_;
    program_ = program;
    options_ = options;
    start_ = start;
    jobs_.clear();
    done_.clear();
    cancel_.store(true);
  }
}

void ProgramPreviewer::request(double tolerance, std::uint64_t token) {
  if (!has_program_) {
    throw TaskError(TaskErrorKind::wrong_state, "no program is open: program.open it first");
  }
  const auto kept = std::find_if(cached_.begin(), cached_.end(),
                                 [&](const auto& entry) { return entry.first == tolerance; });
  if (kept != cached_.end()) {
    ready_.emplace_back(token, RawResult{kept->second});
    std::rotate(kept, kept + 1, cached_.end());  // the newest last
    return;
  }
  if (const auto it = waiting_.find(tolerance); it != waiting_.end()) {
    it->second.push_back(token);
    return;
  }
  if (waiting_.size() >= kMaxWaiting) {
    throw TaskError(TaskErrorKind::busy,
                    "previews at " + std::to_string(kMaxWaiting) +
                        " other tolerances are being worked out: ask again once they are answered");
  }
  waiting_[tolerance].push_back(token);
  {
    std::lock_guard lock(worker_.mutex());
    jobs_.push_back({generation_, tolerance});
  }
  worker_.wake();
}

std::vector<std::pair<std::uint64_t, TaskOutcome>> ProgramPreviewer::take() {
  std::vector<Done> done;
  std::uint64_t generation = 0;
  {
    std::lock_guard lock(worker_.mutex());
    done.swap(done_);
    generation = generation_;
  }
  for (auto& result : done) {
    if (result.generation != generation) continue;
    const auto it = waiting_.find(result.tolerance);
    if (it != waiting_.end()) {
      for (const auto token : it->second)
        ready_.emplace_back(token, RawResult{result.json});
      waiting_.erase(it);
    }
    if (cached_.size() >= kCached) cached_.erase(cached_.begin());
    cached_.emplace_back(result.tolerance, std::move(result.json));
  }
  return std::exchange(ready_, {});
}

void ProgramPreviewer::work(WorkerThread::Lock& lock) {
  const Job job = jobs_.front();
  jobs_.pop_front();
  const std::filesystem::path program = program_;
  pipeline::CheckOptions check;
  check.interp = options_;
  check.machine = &machine_;
  check.start_machine = start_;
  check.max_problems = 1;
  check.max_seconds = kMaxSeconds;
  check.max_seconds_cpu = true;
  check.cancel = &cancel_;
  cancel_.store(false);
  lock.unlock();
  pipeline::PreviewOptions options;
  options.tolerance = job.tolerance;
  const auto preview = pipeline::preview_program(program, check, options);
  std::shared_ptr<const std::string> json;
  if (!preview.report.cancelled) {
    nlohmann::json object = pipeline::preview_json(preview);
    object["path"] = program.string();
    object["tolerance_asked"] = job.tolerance;
    json = std::make_shared<const std::string>(
        object.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  lock.lock();
  if (json && job.generation == generation_) done_.push_back({job.generation, job.tolerance, json});
}

}  // namespace cncd::daemon
