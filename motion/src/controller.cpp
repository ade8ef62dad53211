#include "cncd/motion/controller.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "cncd/motion/planner.hpp"
#include "jog_problem.hpp"

// GCC names the sanitizers with macros, clang through __has_feature.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CNCD_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define CNCD_SANITIZED 1
#endif
#endif
#ifndef CNCD_SANITIZED
#define CNCD_SANITIZED 0
#endif

namespace cncd::motion {
namespace {

std::int64_t to_ns(const timespec& t) {
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

timespec from_ns(std::int64_t ns) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  t.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  return t;
}

// Touches the stack the servo thread will use so that no page fault happens inside the loop.
void prefault_stack() {
  constexpr std::size_t kBytes = 256 * 1024;
  char stack[kBytes];
  std::memset(stack, 0, kBytes);
  // Keeps the compiler from dropping the writes to a buffer nobody reads.
  asm volatile("" : : "r"(stack) : "memory");
}

}  // namespace

struct MotionController::Impl {
  explicit Impl(const config::MachineConfig& c) : config(c), kins(make_kinematics(c)), planner(c) {}

  const config::MachineConfig& config;
  std::unique_ptr<const Kinematics> kins;
  Planner planner;
  std::vector<drivers::DriverInstance> drivers;
  std::unique_ptr<ServoLoop> loop;
  std::thread thread;
  std::atomic<bool> running{false};
  std::vector<std::string> warnings;
  std::string enqueue_error;
  std::uint64_t pushed = 0;             // segments handed to the servo thread since start()
  std::vector<double> start_positions;  // empty = where the drives stand

  // Hands the planner's final segments to the servo thread; false when the ring is full.
  bool pump() {
    auto& out = planner.output();
    while (!out.empty()) {
      if (!loop->segments().push(out.front())) return false;
      out.pop_front();
      ++pushed;
    }
    return true;
  }

  // Hands a command to the servo thread and waits until a cycle has applied it (a period or
  // two), so that the caller's next status read already reflects it.
  void send(Command::Kind kind, std::uint32_t mask = 0) {
    Command command;
    command.kind = kind;
    command.joint_mask = mask;
    send(command);
  }
  void send(const Command& command) {
    if (!loop) return;
    const std::uint64_t before = loop->status().sequence;
    // The command ring is drained every period; it is full only when the servo thread is not
    // running, and then there is nobody to act on the command anyway.
    if (!loop->commands().push(command) || !running.load()) return;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (loop->status().sequence < before + 2 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }

  // What the servo thread obtained from the OS before its first cycle.
  struct RtSetup {
    int sched_error = 0;     // errno of pthread_setschedparam, 0 = SCHED_FIFO granted
    int affinity_error = 0;  // errno of pthread_setaffinity_np, 0 = pinned or not asked
  };

  // Asks for SCHED_FIFO and the configured CPU on the calling thread. Non-RT (runs once on the
  // servo thread before its loop).
  RtSetup setup_rt_thread() const {
    RtSetup setup;
    sched_param param{};
    param.sched_priority = config.cncd.rt_priority;
    setup.sched_error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (config.cncd.rt_cpu >= 0) {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(static_cast<std::size_t>(config.cncd.rt_cpu), &set);
      setup.affinity_error = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    }
    // Ordinary threads have their timer wake-ups coalesced by up to 50 µs; when SCHED_FIFO is
    // refused this keeps the fallback as punctual as the scheduler allows.
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    prefault_stack();
    return setup;
  }

  // The servo thread's body: fixed-period absolute sleeps, one cycle per period.
  void run() {
    const RtSetup setup = setup_rt_thread();
    loop->set_rt_flags(setup.sched_error == 0, locked);
    rt_setup = setup;
    setup_done.store(true, std::memory_order_release);

    const std::int64_t period = config.servo_period_ns;
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    std::int64_t next = to_ns(now) + period;
    while (running.load(std::memory_order_acquire)) {
      const timespec deadline = from_ns(next);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
      }
      clock_gettime(CLOCK_MONOTONIC, &now);
      const std::int64_t woke = to_ns(now);
      loop->cycle(woke - next);
      next += period;
      // After a long stall, skip the missed periods instead of running them back to back.
      if (woke - next > 10 * period) next = woke + period;
    }
  }

  // Waits (non-RT, bounded) for the servo thread to report its scheduling and turns what the
  // OS refused into warnings.
  void collect_rt_warnings() {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (!setup_done.load(std::memory_order_acquire)) {
      if (std::chrono::steady_clock::now() > deadline) {
        warnings.push_back("the servo thread did not report its scheduling within 2 s");
        return;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (rt_setup.sched_error != 0) {
      warnings.push_back("SCHED_FIFO priority " + std::to_string(config.cncd.rt_priority) +
                         " refused (" + std::strerror(rt_setup.sched_error) +
                         "): the servo thread runs without real-time scheduling and its "
                         "timing will suffer; grant CAP_SYS_NICE or LimitRTPRIO");
    }
    if (rt_setup.affinity_error != 0) {
      warnings.push_back("pinning the servo thread to CPU " + std::to_string(config.cncd.rt_cpu) +
                         " refused (" + std::strerror(rt_setup.affinity_error) +
                         "): it runs on any CPU");
    }
  }

  bool locked = false;
  std::atomic<bool> setup_done{false};
  RtSetup rt_setup;  // written by the servo thread before setup_done, read after it
};

MotionController::MotionController(const config::MachineConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

MotionController::~MotionController() {
  stop();
}

std::string MotionController::start(std::vector<drivers::DriverInstance> drivers) {
  if (impl_->running.load()) return "";
  const auto& config = impl_->config;
  std::vector<bool> driven(config.joints.size(), false);
  std::vector<DriverBinding> bindings;
  for (const auto& instance : drivers) {
    if (!instance.driver) return "a driver is missing";
    for (const int joint : instance.joints) {
      if (joint < 0 || joint >= static_cast<int>(driven.size()) ||
          driven[static_cast<std::size_t>(joint)])
        return "joint " + std::to_string(joint) + " is not a joint a driver may drive";
      driven[static_cast<std::size_t>(joint)] = true;
    }
    bindings.push_back(DriverBinding{instance.driver.get(), instance.joints});
  }
  for (std::size_t j = 0; j < driven.size(); ++j) {
    if (!driven[j]) return "joint " + std::to_string(j) + " has no driver";
  }
  impl_->loop.reset();
  impl_->drivers = std::move(drivers);
  impl_->loop = std::make_unique<ServoLoop>(config, std::move(bindings));
  if (!impl_->start_positions.empty()) {
    JointArray joints{};
    const std::size_t n = std::min(impl_->start_positions.size(), joints.size());
    std::copy_n(impl_->start_positions.begin(), n, joints.begin());
    impl_->loop->set_start_positions(joints);
    impl_->start_positions.clear();
  }
  for (auto& instance : impl_->drivers)
    instance.driver->enable();

  impl_->warnings.clear();
  if (CNCD_SANITIZED) {
    impl_->warnings.push_back("memory not locked: sanitizer builds reserve too much to lock");
  } else if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    impl_->locked = true;
  } else {
    impl_->warnings.push_back(std::string("mlockall refused (") + std::strerror(errno) +
                              "): servo thread memory may be paged out; grant CAP_IPC_LOCK or "
                              "LimitMEMLOCK=infinity");
  }
  impl_->pushed = 0;
  impl_->planner.reset(AxisPose{});
  impl_->setup_done.store(false);
  impl_->running.store(true);
  impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
  impl_->collect_rt_warnings();
  return "";
}

void MotionController::set_start_positions(const std::vector<double>& joints) {
  impl_->start_positions = joints;
}

void MotionController::stop() {
  if (!impl_->running.exchange(false)) return;
  impl_->thread.join();
  for (auto& instance : impl_->drivers)
    instance.driver->disable();
  if (impl_->locked) {
    munlockall();
    impl_->locked = false;
  }
}

MotionController::EnqueueResult MotionController::enqueue(const Move& move) {
  if (!impl_->loop) {
    impl_->enqueue_error = "motion is not started";
    return EnqueueResult::refused;
  }
  const Status status = impl_->loop->status();
  if (status.machine != MachineState::on) {
    impl_->enqueue_error = "machine is not on";
    return EnqueueResult::refused;
  }
  // Homing moves the joints and an abort flushes whatever is queued: a move planned now would
  // start from the wrong place or vanish.
  if (status.motion == MotionState::homing || status.motion == MotionState::stopping ||
      status.motion == MotionState::jogging) {
    impl_->enqueue_error = status.motion == MotionState::homing    ? "the machine is homing"
                           : status.motion == MotionState::jogging ? "the machine is jogging"
                                                                   : "the machine is stopping "
                                                                     "after an abort";
    return EnqueueResult::refused;
  }
  if (!impl_->pump()) return EnqueueResult::full;
  // With nothing held back and every segment done, the commanded position is where the next
  // move starts (after homing, an abort or a jog it differs from the last planned end).
  if (!impl_->planner.holding() && status.segments_done == impl_->pushed)
    impl_->planner.reset(status.commanded);
  bool homed = true;
  for (int j = 0; j < status.joint_count; ++j)
    homed = homed && status.homed[static_cast<std::size_t>(j)];
  if (!impl_->planner.push(move, homed, impl_->enqueue_error)) return EnqueueResult::refused;
  impl_->pump();
  return EnqueueResult::queued;
}

MotionController::EnqueueResult MotionController::flush() {
  impl_->planner.flush();
  if (!impl_->loop) return EnqueueResult::queued;
  return impl_->pump() ? EnqueueResult::queued : EnqueueResult::full;
}

MoveQueue::Push MotionController::push_move(const Move& move) {
  switch (enqueue(move)) {
    case EnqueueResult::full:
      return Push::full;
    case EnqueueResult::refused:
      return Push::refused;
    default:
      return Push::accepted;
  }
}

void MotionController::discard() {
  impl_->planner.reset(impl_->planner.end());
}

const std::string& MotionController::enqueue_error() const {
  return impl_->enqueue_error;
}

std::size_t MotionController::queue_space() const {
  if (!impl_->loop) return 0;
  return ServoLoop::SegmentRing::capacity() - impl_->loop->segments().size();
}

void MotionController::estop() {
  impl_->send(Command::Kind::estop);
}
void MotionController::reset_estop() {
  impl_->send(Command::Kind::reset_estop);
}
void MotionController::machine_on() {
  impl_->send(Command::Kind::on);
}
void MotionController::machine_off() {
  impl_->send(Command::Kind::off);
}
void MotionController::home(std::uint32_t joint_mask) {
  impl_->send(Command::Kind::home, joint_mask);
}
void MotionController::abort() {
  discard();
  impl_->send(Command::Kind::abort);
}
void MotionController::pause() {
  impl_->send(Command::Kind::pause);
}
void MotionController::resume() {
  impl_->send(Command::Kind::resume);
}
namespace {
Command with_ratio(Command::Kind kind, double ratio) {
  Command command;
  command.kind = kind;
  command.velocity = ratio;
  return command;
}
Command with_id(Command::Kind kind, std::uint32_t id) {
  Command command;
  command.kind = kind;
  command.id = id;
  return command;
}
}  // namespace

void MotionController::set_feed_override(double ratio) {
  impl_->send(with_ratio(Command::Kind::feed_override, ratio));
}
void MotionController::set_rapid_override(double ratio) {
  impl_->send(with_ratio(Command::Kind::rapid_override, ratio));
}
void MotionController::set_spindle_override(double ratio) {
  impl_->send(with_ratio(Command::Kind::spindle_override, ratio));
}
void MotionController::release_hold(std::uint32_t hold_id) {
  impl_->send(with_id(Command::Kind::release, hold_id));
}
void MotionController::end_wait(WaitStatus::Kind kind, std::uint64_t since) {
  Command command = with_id(Command::Kind::end_wait, static_cast<std::uint32_t>(kind));
  command.since = since;
  impl_->send(command);
}
void MotionController::set_panel_lights(std::uint32_t bits) {
  impl_->send(with_id(Command::Kind::panel_lights, bits));
}
void MotionController::hold_io_at_rest(bool restore) {
  impl_->send(with_id(Command::Kind::io_hold, restore ? 1 : 0));
}

std::string MotionController::jog_start(int axis, double velocity_per_s) {
  if (!impl_->loop) return "motion is not started";
  if (!std::isfinite(velocity_per_s) || velocity_per_s == 0)
    return "the jog velocity must not be 0";
  if (auto problem = jog_problem(impl_->config, *impl_->kins, impl_->loop->status(), axis,
                                 velocity_per_s > 0 ? 1.0 : -1.0);
      !problem.empty())
    return problem;
  Command command;
  command.kind = Command::Kind::jog_start;
  set_jog_target(command, axis);
  command.velocity = velocity_per_s;
  impl_->send(command);
  return "";
}

std::string MotionController::jog_increment(int axis, double distance, double speed_per_s) {
  if (!impl_->loop) return "motion is not started";
  if (!std::isfinite(distance) || distance == 0) return "the jog distance must not be 0";
  if (!std::isfinite(speed_per_s) || speed_per_s <= 0) return "the jog speed must be above 0";
  const Status status = impl_->loop->status();
  if (auto problem =
          jog_problem(impl_->config, *impl_->kins, status, axis, distance > 0 ? 1.0 : -1.0);
      !problem.empty())
    return problem;
  if (status.motion == MotionState::jogging) return "the machine is jogging";
  Command command;
  command.kind = Command::Kind::jog_increment;
  set_jog_target(command, axis);
  command.distance = distance;
  command.velocity = speed_per_s;
  impl_->send(command);
  return "";
}

void MotionController::jog_stop(int axis) {
  Command command;
  command.kind = Command::Kind::jog_stop;
  set_jog_target(command, axis);
  impl_->send(command);
}

std::int64_t MotionController::feedback_deadline_ns() const {
  std::int64_t deadline = 0;
  for (const auto& instance : impl_->drivers)
    deadline = std::max(deadline, instance.driver->feedback_deadline_ns());
  return deadline;
}

Status MotionController::status() const {
  if (!impl_->loop) {
    Status idle;
    idle.joint_count = static_cast<int>(impl_->config.joints.size());
    return idle;
  }
  return impl_->loop->status();
}

bool MotionController::poll_event(Event& event) {
  return impl_->loop && impl_->loop->events().pop(event);
}

const std::vector<std::string>& MotionController::start_warnings() const {
  return impl_->warnings;
}

}  // namespace cncd::motion
