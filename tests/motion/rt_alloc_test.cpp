// The servo period allocates nothing and takes no lock: the servo loop, on the simulated
// driver, runs a program of lines, arcs, blends and a dwell, overrides and a hold, jogs,
// homing, a drive fault, an estop and their recovery, while this executable's operator new and
// delete, and its pthread mutex, rwlock, spinlock and semaphore waits (which forward to the C
// library's), count every call made inside ServoLoop::cycle(). The planner and the test itself
// allocate and lock freely between periods.
//
// Sanitizer runtimes bring their own operator new and intercept the locks; the test is skipped
// there.
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/drivers/sim_driver.hpp"
#include "cncd/motion/planner.hpp"
#include "cncd/motion/servo_loop.hpp"
#include "machine_fixture.hpp"
#include "panel_fixture.hpp"
#include "path_distance.hpp"
#include "rt_alloc_hooks.hpp"

namespace rt_hooks = cncd::test::rt_hooks;

namespace cncd::motion {
namespace {

using Kind = Command::Kind;

// The servo loop on the simulated driver, every cycle() counted.
class Rig {
 public:
  // `panel`: a driver of no joints that reports the panel's inputs.
  explicit Rig(const config::MachineConfig& config, drivers::Driver* panel = nullptr)
      : config_(config), planner_(config_) {
    for (int j = 0; j < static_cast<int>(config_.joints.size()); ++j)
      joints_.push_back(j);
    EXPECT_EQ(sim_.configure(config_, joints_), "");
    std::vector<DriverBinding> bindings{DriverBinding{&sim_, joints_}};
    if (panel != nullptr) bindings.push_back(DriverBinding{panel, {}});
    loop_ = std::make_unique<ServoLoop>(config_, std::move(bindings));
  }

  void cycles(int n) {
    for (int i = 0; i < n; ++i) {
      rt_hooks::in_period = true;
      loop_->cycle(0);
      rt_hooks::in_period = false;
      ++periods_;
      Event event;
      while (loop_->events().pop(event))
        events_.emplace_back(event.text);
    }
  }
  void command(Kind kind, std::uint32_t mask = 0, int axis = 0, double velocity = 0,
               double distance = 0) {
    Command c;
    c.kind = kind;
    c.joint_mask = mask;
    c.axis = axis;
    c.velocity = velocity;
    c.distance = distance;
    ASSERT_TRUE(loop_->commands().push(c));
    cycles(1);
  }
  void queue(const Move& move) {
    const Status s = loop_->status();
    if (!planner_.holding() && s.segments_done == pushed_) planner_.reset(s.commanded);
    std::string error;
    ASSERT_TRUE(planner_.push(move, true, error)) << error;
    pump();
  }
  // Runs until the loop stands idle with nothing queued; the planner's output is pumped in
  // between periods, as the task thread does.
  void run_until_idle(int max_cycles = 200'000) {
    planner_.flush();
    for (int i = 0; i < max_cycles; ++i) {
      pump();
      cycles(1);
      const Status s = loop_->status();
      if (s.motion == MotionState::idle && s.queued == 0 && planner_.output().empty()) return;
    }
    ADD_FAILURE() << "motion did not finish within " << max_cycles << " cycles";
  }
  // Releases the move the planner holds back.
  void flush() {
    planner_.flush();
    pump();
  }
  Status status() const { return loop_->status(); }
  drivers::SimDriver& sim() { return sim_; }
  long periods() const { return periods_; }
  // Whether the loop posted an event starting with `prefix`.
  bool saw(const std::string& prefix) const {
    for (const auto& e : events_) {
      if (e.rfind(prefix, 0) == 0) return true;
    }
    return false;
  }

 private:
  void pump() {
    auto& out = planner_.output();
    while (!out.empty() && loop_->segments().push(out.front())) {
      out.pop_front();
      ++pushed_;
    }
  }

  config::MachineConfig config_;
  std::vector<int> joints_;
  drivers::SimDriver sim_;
  std::unique_ptr<ServoLoop> loop_;
  Planner planner_;
  std::uint64_t pushed_ = 0;
  long periods_ = 0;
  std::vector<std::string> events_;
};

Move blended(Move m) {
  m.path_mode = Move::PathMode::blend;
  m.tolerance = 0.05;
  return m;
}

void program(Rig& rig) {
  using test::arc_to;
  using test::line_to;
  rig.queue(line_to(Move::Kind::traverse, 10, 0, 5));
  // The spindle, coolant, outputs and waits done where the path rests (an orientation to 2.5
  // degrees among them), and outputs set with the start of a move.
  const auto action = [&rig](motion::IoAction::Kind kind) {
    Move m;
    m.kind = Move::Kind::action;
    m.action.kind = kind;
    m.action.direction = 1;
    m.action.rpm = 1000;
    m.action.flood = true;
    m.action.on = true;
    m.action.value = 2.5;
    m.action.timeout_s = 5;
    rig.queue(m);
  };
  using Io = motion::IoAction::Kind;
  for (const Io kind : {Io::spindle, Io::coolant, Io::digital_output, Io::analog_output,
                        Io::spindle_override_enable, Io::wait_input, Io::wait_at_speed,
                        Io::orient_spindle, Io::wait_orient, Io::spindle})
    action(kind);
  Move synced = blended(line_to(Move::Kind::feed, 10, 0, 0, 20));
  synced.sync.set = 1u << 3;
  synced.sync.analog_mask = 1u;
  synced.sync.analog[0] = 1.5;
  rig.queue(synced);
  rig.queue(blended(line_to(Move::Kind::feed, 30, 0, 0, 40)));
  rig.queue(blended(arc_to(40, 10, 30, 10, 1, 40)));  // quarter, ccw
  rig.queue(blended(arc_to(40, 10, 40, 0, -1, 40)));  // full circle, cw
  rig.queue(blended(line_to(Move::Kind::feed, 40, 30, 0, 40)));
  for (int k = 0; k < 40; ++k)  // a dense raster of short blended moves
    rig.queue(blended(line_to(Move::Kind::feed, 40 + (k % 2) * 0.5, 30 + k * 0.2, 0, 60)));
  Move dwell;
  dwell.kind = Move::Kind::dwell;
  dwell.dwell_s = 0.05;
  rig.queue(dwell);
  rig.queue(line_to(Move::Kind::traverse, 0, 0, 5));
}

// Counts since the last call.
struct Counted {
  long allocs;
  long frees;
  long locks;
};
Counted take_counts() {
  return {rt_hooks::period_allocs.exchange(0), rt_hooks::period_frees.exchange(0),
          rt_hooks::period_locks.exchange(0)};
}

#define EXPECT_PERIODS_RT_SAFE(phase)                                                         \
  do {                                                                                        \
    const Counted counted = take_counts();                                                    \
    EXPECT_EQ(counted.allocs, 0) << (phase) << ": operator new called in the servo period";   \
    EXPECT_EQ(counted.frees, 0) << (phase) << ": operator delete called in the servo period"; \
    EXPECT_EQ(counted.locks, 0) << (phase) << ": a lock taken in the servo period";           \
  } while (0)

void run_everything(Rig& rig) {
  take_counts();
  rig.command(Kind::reset_estop);
  rig.command(Kind::on);
  rig.command(Kind::home, 0xFFFFFFFFu);
  rig.run_until_idle();
  ASSERT_EQ(rig.status().machine, MachineState::on);
  ASSERT_TRUE(rig.status().homed[0]);
  EXPECT_PERIODS_RT_SAFE("homing");

  program(rig);
  rig.run_until_idle();
  EXPECT_EQ(rig.status().fault_reason[0], '\0') << rig.status().fault_reason;
  EXPECT_PERIODS_RT_SAFE("program");

  // Overrides and a hold in the middle of a long move, then an abort.
  rig.queue(test::line_to(Move::Kind::feed, 300, 0, 0, 100));
  rig.queue(test::line_to(Move::Kind::feed, 300, 300, 0, 100));
  rig.flush();
  rig.cycles(200);
  rig.command(Kind::feed_override, 0, 0, 0.5);
  rig.cycles(100);
  rig.command(Kind::pause);
  rig.cycles(300);
  EXPECT_EQ(rig.status().motion, MotionState::paused);
  rig.command(Kind::resume);
  rig.cycles(200);
  rig.command(Kind::abort);
  rig.run_until_idle();
  rig.command(Kind::feed_override, 0, 0, 1.0);
  EXPECT_PERIODS_RT_SAFE("overrides, hold and abort");

  // Jogs: continuous, reversed, stopped; an increment; one refused (an event with words).
  rig.command(Kind::jog_start, 0, 0, 50);
  rig.cycles(200);
  rig.command(Kind::jog_start, 0, 0, -50);
  rig.cycles(200);
  rig.command(Kind::jog_stop, 0, 0);
  rig.run_until_idle();
  rig.command(Kind::jog_increment, 0, 1, 20, 2.5);
  rig.run_until_idle();
  rig.command(Kind::jog_start, 0, 7, 50);
  rig.cycles(10);
  EXPECT_TRUE(rig.saw("jog ignored: the machine has no such axis"));
  EXPECT_PERIODS_RT_SAFE("jogging");

  // A drive fault in the middle of a move, and the recovery.
  rig.queue(test::line_to(Move::Kind::feed, 0, 0, -20, 50));
  rig.flush();
  rig.cycles(100);
  EXPECT_EQ(rig.status().motion, MotionState::moving);
  rig.sim().set_fault(1, true);
  rig.cycles(10);
  EXPECT_EQ(rig.status().machine, MachineState::off);
  EXPECT_TRUE(rig.saw("joint 1: drive fault"));
  rig.sim().set_fault(1, false);
  rig.command(Kind::on);
  rig.command(Kind::home, 0xFFFFFFFFu);
  rig.run_until_idle();
  rig.queue(test::line_to(Move::Kind::feed, 5, 5, 0, 50));
  rig.run_until_idle();
  EXPECT_EQ(rig.status().fault_reason[0], '\0') << rig.status().fault_reason;
  EXPECT_PERIODS_RT_SAFE("drive fault and recovery");

  // A tripped limit switch, stale feedback and the estop input, each recovered from.
  rig.sim().set_limit(0, false, true);
  rig.cycles(5);
  rig.sim().set_limit(0, false, false);
  rig.command(Kind::on);
  rig.sim().set_stale(2, true);
  rig.cycles(5);
  rig.sim().set_stale(2, false);
  rig.command(Kind::on);
  rig.sim().set_estop_input(true);
  rig.cycles(5);
  EXPECT_EQ(rig.status().machine, MachineState::estop);
  EXPECT_TRUE(rig.saw("joint 0: maximum limit switch tripped"));
  EXPECT_TRUE(rig.saw("joint 2: feedback is stale"));
  EXPECT_TRUE(rig.saw("estop input asserted"));
  rig.sim().set_estop_input(false);
  rig.command(Kind::reset_estop);
  rig.command(Kind::on);
  rig.command(Kind::home, 0xFFFFFFFFu);
  rig.run_until_idle();
  program(rig);
  rig.run_until_idle();
  EXPECT_EQ(rig.status().fault_reason[0], '\0') << rig.status().fault_reason;
  rig.command(Kind::estop);
  EXPECT_PERIODS_RT_SAFE("limits, stale feedback, estop and recovery");
  EXPECT_GT(rig.periods(), 10'000);
}

// Every panel input pressed and released, counters wrapping, lights, and the MPG jogging
// in the config's mode; a client jog refused while it moves; counts dropped in estop.
void run_panel(Rig& rig, test::panel::PanelDrive& panel) {
  using test::panel::bit;
  using test::panel::mpg_axis_bit;
  take_counts();
  rig.command(Kind::reset_estop);
  rig.command(Kind::on);
  rig.command(Kind::home, 0xFFFFFFFFu);
  rig.run_until_idle();
  rig.command(Kind::panel_lights, 0, 0, 0, 0);
  panel.bits = {16, 32, 16, 32};
  for (int i = 0; i < 20; ++i) {
    panel.inputs = i % 2 == 0 ? ~std::uint64_t{0} : 0;
    panel.counts[1] += 40'000;
    panel.counts[2] = (panel.counts[2] + 50'000) & 0xFFFF;
    panel.analog[0] = i;
    rig.cycles(15);
  }
  EXPECT_GT(rig.status().panel.presses[0], 0u);
  panel.inputs =
      mpg_axis_bit(0) | bit(config::PanelInput::mpg_enable) | bit(config::PanelInput::mpg_step_100);
  rig.cycles(15);
  for (int i = 0; i < 600; ++i) {
    panel.turn(i < 300 ? 3 : -2);
    rig.cycles(1);
    if (i == 100) {
      EXPECT_TRUE(rig.status().panel.mpg_jogging);
      rig.command(Kind::jog_start, 0, 1, 50);
    }
  }
  rig.run_until_idle();
  EXPECT_TRUE(rig.saw("jog ignored: the panel's MPG is jogging"));
  rig.command(Kind::estop);
  panel.turn(1000);
  rig.cycles(20);
  EXPECT_PERIODS_RT_SAFE("panel");
}

class RtAllocation : public ::testing::Test {
 protected:
  void SetUp() override {
    if (CNCD_RT_ALLOC_SANITIZED)
      GTEST_SKIP() << "the sanitizer runtime replaces operator new; allocation counting needs "
                      "the plain build";
  }
};

TEST_F(RtAllocation, TheCountingHookSeesAnAllocationInThePeriod) {
  // The hook itself works: an allocation with the flag set is counted.
  take_counts();
  rt_hooks::in_period = true;
  auto* p = new std::vector<int>(3);
  delete p;
  rt_hooks::in_period = false;
  const Counted counted = take_counts();
  EXPECT_EQ(counted.allocs, 2);
  EXPECT_EQ(counted.frees, 2);
  EXPECT_EQ(counted.locks, 0);
}

TEST_F(RtAllocation, TheCountingHookSeesALockInThePeriod) {
  std::mutex mutex;
  std::shared_mutex shared;
  sem_t semaphore;
  ASSERT_EQ(sem_init(&semaphore, 0, 2), 0);
  take_counts();
  rt_hooks::in_period = true;
  { const std::lock_guard guard(mutex); }
  if (mutex.try_lock()) mutex.unlock();
  { const std::shared_lock reading(shared); }
  { const std::unique_lock writing(shared); }
  sem_wait(&semaphore);
  sem_trywait(&semaphore);
  rt_hooks::in_period = false;
  sem_destroy(&semaphore);
  const Counted counted = take_counts();
  EXPECT_EQ(counted.locks, 6);
  EXPECT_EQ(counted.allocs, 0);
}

TEST_F(RtAllocation, TrapezoidalServoPeriodsNeverAllocate) {
  Rig rig(test::small_mill());
  run_everything(rig);
}

TEST_F(RtAllocation, SCurveServoPeriodsNeverAllocate) {
  auto config = test::small_mill();
  config.scurve = true;
  config.max_linear_jerk = 50'000;
  Rig rig(config);
  run_everything(rig);
}

TEST_F(RtAllocation, PanelServoPeriodsNeverAllocate) {
  for (const auto mode :
       {config::PanelConfig::MpgMode::position, config::PanelConfig::MpgMode::velocity}) {
    test::panel::PanelDrive panel;
    Rig rig(test::panel::panel_mill(mode, 4, 10), &panel);
    run_everything(rig);
    run_panel(rig, panel);
  }
}

}  // namespace
}  // namespace cncd::motion
