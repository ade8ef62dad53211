#include "cncd/drivers/gpio_driver.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cmath>

#include "panel_wiring.hpp"
#include "pwm_encoder.hpp"
#include "stepgen.hpp"

#include "monotonic_clock.hpp"

namespace cncd::drivers {
namespace {

std::int64_t to_ns(const timespec& t) {
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

}  // namespace

GpioDriver::GpioDriver() {
  digital_in_.fill(-1);
  panel_in_.fill(-1);
}

GpioDriver::~GpioDriver() {
  disable();
}

void GpioDriver::enable() {
  if (backend_) backend_->start();
  if (running_.exchange(true)) return;
  seen_periods_ = periods_.load();
  silent_reads_ = 0;
  stale_ = false;
  if (!manual_clock_) base_thread_ = std::thread([this] { base_loop(); });
}

void GpioDriver::disable() {
  if (running_.exchange(false) && base_thread_.joinable()) base_thread_.join();
  if (backend_) backend_->stop();
}

void GpioDriver::write(const JointCommand* commands, int count) noexcept {
  CommandBlock block;
  const int n = std::min(count, static_cast<int>(joints_.size()));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    block.position[k] = commands[i].position;
    block.velocity[k] = commands[i].velocity;
    block.enable[k] = commands[i].enable;
  }
  mailbox_.store(block);
}

void GpioDriver::read(JointFeedback* feedback, int count) noexcept {
  // Once per servo period (read() comes before read_io()).
  const std::uint64_t periods = periods_.load(std::memory_order_relaxed);
  if (!running_.load(std::memory_order_relaxed) || periods != seen_periods_) {
    seen_periods_ = periods;
    silent_reads_ = 0;
  } else if (silent_reads_ < stale_reads_) {
    ++silent_reads_;
  }
  stale_ = silent_reads_ >= stale_reads_;
  const bool stale = stale_;
  const int n = std::min(count, static_cast<int>(joints_.size()));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const JointLines& jl = joints_[k];
    JointFeedback& fb = feedback[i];
    fb.position = static_cast<double>(counts_[k].load(std::memory_order_relaxed)) / jl.scale;
    fb.home_switch = input(jl.home);
    fb.min_limit = input(jl.min_limit);
    fb.max_limit = input(jl.max_limit);
    fb.fault = false;
    fb.stale = stale;
  }
}

void GpioDriver::write_io(const IoCommand& command) noexcept {
  IoBlock block;
  block.spindle_enable = command.spindle.enable;
  block.spindle_reverse = command.spindle.reverse;
  block.spindle_rpm = command.spindle.rpm;
  block.spindle_sequence = command.spindle.sequence;
  block.flood = command.flood;
  block.mist = command.mist;
  block.digital = command.digital;
  block.panel = command.panel;
  io_mailbox_.store(block);
}

void GpioDriver::read_io(IoFeedback& feedback) noexcept {
  for (std::size_t n = 0; n < digital_in_.size(); ++n) {
    if (digital_in_[n] < 0) continue;
    const std::uint32_t bit = 1u << n;
    feedback.digital = input(digital_in_[n]) ? feedback.digital | bit : feedback.digital & ~bit;
  }
  PanelFeedback& panel = feedback.panel;
  for (std::size_t i = 0; i < panel_in_.size(); ++i) {
    if (panel_in_[i] >= 0)
      panel.inputs = with_bit(panel.inputs, static_cast<int>(i), input(panel_in_[i]));
  }
  for (std::size_t c = 0; c < panel_encoders_.size(); ++c) {
    if (panel_encoders_[c].a < 0) continue;
    panel.counts[c] = panel_counts_[c].load(std::memory_order_relaxed);
    panel.counter_bits[c] = 32;
  }
  if (!spindle_) return;
  // While the base thread is publishing, the previous period's values do.
  spindle_state_.try_load(spindle_feedback_);
  SpindleFeedback& fb = feedback.spindle;
  fb.present = true;
  fb.rpm = spindle_feedback_.rpm;
  fb.has_at_speed = false;
  fb.at_speed = false;
  fb.fault = false;
  fb.stale = stale_;
  fb.has_position = encoder_ != nullptr;
  fb.revolutions = encoder_ ? spindle_feedback_.revolutions : 0;
  fb.time_ns = encoder_ ? spindle_feedback_.time_ns : 0;
  fb.acknowledged = spindle_feedback_.acknowledged;
}

void GpioDriver::set_output(const OutputLine& line, bool on) noexcept {
  if (line.output >= 0) {
    output_levels_[static_cast<std::size_t>(line.output)] = on != line.active_low ? 1 : 0;
  }
}

void GpioDriver::run_io(double dt, std::int64_t time_ns) noexcept {
  IoBlock latest;
  if (io_mailbox_.version() != io_version_ && io_mailbox_.try_load(latest)) {
    io_ = latest;
    io_version_ = io_mailbox_.version();
  }
  set_output(flood_, io_.flood);
  set_output(mist_, io_.mist);
  for (std::size_t n = 0; n < digital_out_.size(); ++n)
    set_output(digital_out_[n], ((io_.digital >> n) & 1u) != 0);
  for (std::size_t l = 0; l < panel_light_.size(); ++l)
    set_output(panel_light_[l], ((io_.panel >> l) & 1u) != 0);
  if (!spindle_) return;
  const double rpm = std::abs(io_.spindle_rpm);
  const double target = !io_.spindle_enable ? 0.0 : io_.spindle_reverse ? -rpm : rpm;
  // Signed, so that a change of direction ramps through zero.
  const double step = spindle_acceleration_ * dt;
  if (spindle_acceleration_ <= 0 || std::abs(target - ramp_rpm_) <= step) {
    ramp_rpm_ = target;
  } else {
    ramp_rpm_ += target > ramp_rpm_ ? step : -step;
  }
  set_output(spindle_enable_, io_.spindle_enable);
  set_output(spindle_dir_, ramp_rpm_ < 0 || (ramp_rpm_ == 0 && target < 0));
  if (pwmgen_) {
    const double duty =
        io_.spindle_enable
            ? pwm_min_duty_ + (1 - pwm_min_duty_) * std::abs(ramp_rpm_) / spindle_max_rpm_
            : 0.0;
    set_output(spindle_pwm_, pwmgen_->tick(duty));
  }
  SpindleState state;
  if (encoder_) {
    const auto level = [&](int index) {
      return index >= 0 && input_levels_[static_cast<std::size_t>(index)] != 0;
    };
    encoder_->sample(level(encoder_a_), level(encoder_b_), level(encoder_index_), time_ns);
    state.rpm = encoder_->rpm();
    state.revolutions = encoder_->revolutions();
    state.time_ns = time_ns;
  } else {
    state.rpm = std::abs(ramp_rpm_);
  }
  state.acknowledged = io_.spindle_sequence;
  spindle_state_.store(state);
}

void GpioDriver::read_inputs(MachineInputs& inputs) noexcept {
  if (input(estop_input_)) inputs.estop = true;
  if (probe_input_ >= 0 && (probe_touched_.exchange(false, std::memory_order_relaxed) ||
                            probe_level_.load(std::memory_order_relaxed))) {
    inputs.probe = true;
  }
}

std::int64_t GpioDriver::step_count(int index) const noexcept {
  if (index < 0 || index >= kMaxJoints) return 0;
  return counts_[static_cast<std::size_t>(index)].load(std::memory_order_relaxed);
}

bool GpioDriver::input(int index) const noexcept {
  return index >= 0 &&
         inputs_[static_cast<std::size_t>(index)].published.load(std::memory_order_relaxed);
}

GpioDriver::BaseStats GpioDriver::base_stats() const noexcept {
  BaseStats stats;
  stats.periods = periods_.load();
  stats.max_late_ns = max_late_ns_.load();
  if (stats.periods > 0) {
    stats.mean_late_ns =
        static_cast<double>(total_late_ns_.load()) / static_cast<double>(stats.periods);
  }
  return stats;
}

void GpioDriver::sample_panel_encoders() noexcept {
  for (std::size_t c = 0; c < panel_encoders_.size(); ++c) {
    PanelEncoder& e = panel_encoders_[c];
    if (e.a < 0) continue;
    const bool a = (input_levels_[static_cast<std::size_t>(e.a)] != 0) != e.a_low;
    const bool b = (input_levels_[static_cast<std::size_t>(e.b)] != 0) != e.b_low;
    e.decoder.sample(a, b);
    panel_counts_[c].store(e.decoder.count(), std::memory_order_relaxed);
    panel_errors_[c].store(e.decoder.errors(), std::memory_order_relaxed);
  }
}

void GpioDriver::sample_inputs(std::int64_t time_ns) noexcept {
  if (input_count_ == 0) return;
  backend_->read_inputs(input_levels_.data(), time_ns);
  sample_panel_encoders();
  if (probe_input_ >= 0) {
    const Input& probe = inputs_[static_cast<std::size_t>(probe_input_)];
    const bool touching =
        (input_levels_[static_cast<std::size_t>(probe.backend_index)] != 0) != probe.active_low;
    probe_level_.store(touching, std::memory_order_relaxed);
    if (touching) probe_touched_.store(true, std::memory_order_relaxed);
  }
  for (std::size_t i = 0; i < input_count_; ++i) {
    Input& in = inputs_[i];
    const bool asserted = (input_levels_[i] != 0) != in.active_low;
    // A new level counts only after it held for the debounce time.
    if (asserted == in.state) {
      in.pending_ticks = 0;
      continue;
    }
    if (++in.pending_ticks >= in.debounce_ticks) {
      in.state = asserted;
      in.pending_ticks = 0;
      in.published.store(asserted, std::memory_order_relaxed);
    }
  }
}

void GpioDriver::run_base_period(std::int64_t time_ns) noexcept {
  const double dt = static_cast<double>(base_period_ns_) * 1e-9;
  CommandBlock latest;
  // A command being written right now is picked up next period; the base thread never waits.
  if (mailbox_.version() != command_version_ && mailbox_.try_load(latest)) {
    command_ = latest;
    command_version_ = mailbox_.version();
    since_command_s_ = 0;
    for (std::size_t k = 0; k < joints_.size(); ++k) {
      if (primed_[k]) continue;
      stepgens_[k].prime(std::llround(command_.position[k] * joints_[k].scale));
      primed_[k] = true;
    }
  } else {
    since_command_s_ += dt;
  }
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    const JointLines& jl = joints_[k];
    Stepgen& sg = stepgens_[k];
    const bool on = primed_[k] && command_.enable[k];
    sg.tick(command_.position[k] * jl.scale, command_.velocity[k] * jl.scale, since_command_s_, on);
    output_levels_[static_cast<std::size_t>(jl.step_output)] = sg.step_line() ? 1 : 0;
    output_levels_[static_cast<std::size_t>(jl.dir_output)] = sg.dir_line() ? 1 : 0;
    if (jl.enable_output >= 0) {
      output_levels_[static_cast<std::size_t>(jl.enable_output)] =
          on != jl.enable_active_low ? 1 : 0;
    }
    counts_[k].store(sg.count(), std::memory_order_relaxed);
  }
  run_io(dt, time_ns);
  backend_->write_outputs(output_levels_.data(), time_ns);
  sample_inputs(time_ns);
  periods_.fetch_add(1, std::memory_order_relaxed);
}

void GpioDriver::base_loop() noexcept {
  // Above the servo thread, like LinuxCNC's base thread; refused without privileges, and then
  // it runs at normal priority (the daemon already warns about real-time scheduling).
  sched_param param{};
  param.sched_priority = std::min(99, rt_priority_ + 1);
  pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  // Pins need every base period on time. A recording does not: it wakes once per servo period
  // and runs the base periods that came due, each stamped with its own time. A wake-up every
  // 25 us costs most of a CPU on a virtual machine, enough for the kernel's real-time
  // throttling to stop the thread for tens of milliseconds.
  const bool batched = !backend_->drives_pins() && !real_time_recording_;
  const std::int64_t wake_ns =
      batched ? std::max(servo_period_ns_, base_period_ns_) : base_period_ns_;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  std::int64_t due_ns = to_ns(next);  // batched: time of the next base period to run
  while (running_.load(std::memory_order_relaxed)) {
    next.tv_nsec += wake_ns;
    while (next.tv_nsec >= 1'000'000'000) {
      next.tv_nsec -= 1'000'000'000;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    const std::int64_t now = monotonic_ns();
    const std::int64_t late = now - to_ns(next);
    total_late_ns_.fetch_add(late, std::memory_order_relaxed);
    if (late > max_late_ns_.load(std::memory_order_relaxed)) {
      max_late_ns_.store(late, std::memory_order_relaxed);
    }
    if (batched) {
      // After a long stall, the periods missed are dropped as on pins, not run in a burst.
      due_ns = std::max(due_ns, now - 10 * wake_ns);
      for (; due_ns <= now; due_ns += base_period_ns_)
        run_base_period(due_ns);
    } else {
      run_base_period(now);
    }
    // After a long stall, catch up with the clock instead of bursting through missed periods.
    if (late > 10 * wake_ns) clock_gettime(CLOCK_MONOTONIC, &next);
  }
}

}  // namespace cncd::drivers
