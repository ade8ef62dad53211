#include "program_open.hpp"

#include <utility>

#include "cncd/pipeline/program_check.hpp"
#include "program_dirs.hpp"

namespace cncd::daemon {
namespace {

// Refuses a program whose moves leave the soft limits, from where the machine stood and with
// the offsets and tools saved in the parameter file and tool table, or that the interpreter
// stops on: the error cncd-check gives, at the same line, and not part-way through a run.
OpenOutcome check_for_open(std::uint64_t job, const OpenRequest& request,
                           const config::MachineConfig& machine, const std::atomic<bool>& cancel) {
  OpenOutcome out;
  out.job = job;
  out.path = request.path;
  // Every refusal here is the program's.
  const auto fail = [&](const std::string& message) {
    out.error = TaskError(TaskErrorKind::program, message);
    return out;
  };
  const ProgramFile file = find_program(request.path, request.program_dirs);
  if (!file.error.empty()) return fail(file.error);
  out.path = file.path;
  pipeline::CheckOptions options;
  options.interp = request.interp;
  options.machine = &machine;
  options.max_problems = 1;
  options.start_machine = request.start;
  options.max_seconds = ProgramOpener::kMaxCheckSeconds;
  options.max_seconds_cpu = true;
  options.cancel = &cancel;
  const pipeline::CheckReport report = pipeline::check_program(file.path, options);
  if (report.cancelled) return out;  // nobody waits for it
  if (report.stopped) out.warnings.push_back(report.stopped->to_string());
  if (report.limit_violations > 0) {
    std::string message = report.problems.front().to_string();
    if (report.limit_violations > 1) {
      message += " (and " + std::to_string(report.limit_violations - 1) + " more)";
    }
    return fail(message);
  }
  if (report.error) return fail(report.error->to_string());
  out.dialect = report.dialect;
  auto subs = std::make_shared<interp::SubroutineIndex>();
  const auto unread = interp::index_program(
      file.path, *subs, [&cancel] { return cancel.load(std::memory_order_relaxed); });
  if (cancel.load()) return out;
  if (unread) return fail(unread->to_string());
  out.lines = subs->lines;
  out.subs = std::move(subs);
  return out;
}

}  // namespace

ProgramOpener::ProgramOpener(const config::MachineConfig& machine) : machine_(machine) {
  // The servo thread and the control socket come first; the check's time budget counts this
  // thread's processor time, so a busy machine makes it slower, not shorter.
  worker_.start(
      10, [this] { return next_.has_value(); }, [this](WorkerThread::Lock& lock) { work(lock); });
}

ProgramOpener::~ProgramOpener() {
  worker_.stop([this] {
    next_.reset();
    wanted_ = 0;
    cancel_.store(true);
  });
}

std::uint64_t ProgramOpener::start(OpenRequest request) {
  const std::uint64_t job = ++last_job_;
  {
    std::lock_guard lock(worker_.mutex());
    next_.emplace(job, std::move(request));
    wanted_ = job;
    done_.reset();
    cancel_.store(true);
  }
  worker_.wake();
  return job;
}

void ProgramOpener::cancel() {
  std::lock_guard lock(worker_.mutex());
  next_.reset();
  wanted_ = 0;
  done_.reset();
  cancel_.store(true);
}

std::optional<OpenOutcome> ProgramOpener::take() {
  std::lock_guard lock(worker_.mutex());
  return std::exchange(done_, std::nullopt);
}

void ProgramOpener::work(WorkerThread::Lock& lock) {
  auto [job, request] = std::move(*next_);
  next_.reset();
  cancel_.store(false);
  lock.unlock();
  OpenOutcome outcome = check_for_open(job, request, machine_, cancel_);
  lock.lock();
  if (job == wanted_ && !cancel_.load()) done_ = std::move(outcome);
}

}  // namespace cncd::daemon
