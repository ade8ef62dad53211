// Runs the servo thread on a simulated three-axis mill for a while, with moves going back and
// forth, and prints its wake-up error statistics. Prints figures; never fails on timing.
//
//   cncd_servo_jitter [SECONDS] [PERIOD_US] [RT_PRIORITY] [RT_CPU]
//
// Without CAP_SYS_NICE (e.g. `capsh --drop=cap_sys_nice -- -c cncd_servo_jitter`) it shows
// the figures of an ordinary thread.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "bench_mill.hpp"
#include "cncd/motion/controller.hpp"

namespace {

using namespace cncd;

config::MachineConfig bench_mill(std::int64_t period_ns, int priority, int cpu) {
  config::MachineConfig c = bench::three_axis_mill();
  c.servo_period_ns = period_ns;
  c.cncd.rt_priority = priority;
  c.cncd.rt_cpu = cpu;
  return c;
}

double us(std::int64_t ns) {
  return static_cast<double>(ns) / 1000.0;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  const std::int64_t period_ns = argc > 2 ? std::atoll(argv[2]) * 1000 : 1'000'000;
  const int priority = argc > 3 ? std::atoi(argv[3]) : 80;
  const int cpu = argc > 4 ? std::atoi(argv[4]) : -1;
  const auto config = bench_mill(period_ns, priority, cpu);

  motion::MotionController motion(config);
  std::string error;
  auto drivers = drivers::make_drivers(config, error);
  if (error.empty()) error = motion.start(std::move(drivers));
  if (!error.empty()) {
    std::fprintf(stderr, "cncd_servo_jitter: %s\n", error.c_str());
    return 1;
  }
  for (const auto& warning : motion.start_warnings())
    std::printf("warning: %s\n", warning.c_str());
  motion.reset_estop();
  motion.machine_on();
  motion.home(0xFFFFFFFFu);

  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  double x = 100;
  while (std::chrono::steady_clock::now() < end) {
    motion::Move move;
    move.kind = motion::Move::Kind::feed;
    move.end = {x, x / 2, x / 10, 0, 0, 0, 0, 0, 0};
    move.feed = 150;
    if (motion.status().queued < 2 &&
        motion.enqueue(move) == motion::MotionController::EnqueueResult::queued) {
      x = -x;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const motion::Status s = motion.status();
  motion.stop();

  const auto& rt = s.rt;
  std::printf("servo period       %.0f us\n", us(period_ns));
  std::printf("SCHED_FIFO         %s (priority %d)\n", rt.realtime ? "yes" : "no", priority);
  std::printf("memory locked      %s\n", rt.memory_locked ? "yes" : "no");
  std::printf("cycles             %llu\n", static_cast<unsigned long long>(rt.cycles));
  std::printf("segments done      %llu\n", static_cast<unsigned long long>(s.segments_done));
  std::printf("wake-up error p50  <= %.0f us\n", us(rt.wake_error_p50_ns));
  std::printf("wake-up error p99  <= %.0f us\n", us(rt.wake_error_p99_ns));
  std::printf("wake-up error p99.9<= %.0f us\n", us(rt.wake_error_p999_ns));
  std::printf("wake-up error max     %.1f us\n", us(rt.wake_error_max_ns));
  std::printf("overruns           %llu\n", static_cast<unsigned long long>(rt.overruns));
  if (s.fault_reason[0] != '\0') std::printf("fault              %s\n", s.fault_reason);
  return 0;
}
