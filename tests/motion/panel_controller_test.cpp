// One hand on the machine through MotionController, on its real servo thread: a client's jog
// is refused, naming the panel's MPG, while the MPG moves an axis.
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/motion/controller.hpp"
#include "panel_fixture.hpp"

namespace cncd::test::panel {
namespace {

// PanelDrive's inputs and MPG, set from the test's thread while the servo thread reads them.
class ThreadedPanel final : public FakeDriver {
 public:
  ThreadedPanel() : FakeDriver("panel") {}
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    feedback.panel.inputs = inputs.load();
    feedback.panel.counts[0] = mpg.load();
    feedback.panel.counter_bits[0] = 32;
  }
  std::atomic<std::uint64_t> inputs{0};
  std::atomic<std::uint32_t> mpg{0};
};

template <typename Predicate>
bool wait_for(Predicate done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

TEST(PanelController, AClientJogIsRefusedNamingTheMpgWhileItMoves) {
  const config::MachineConfig plain = small_mill();
  const config::MachineConfig config = panel_mill(PanelConfig::MpgMode::position, 1);
  std::string error;
  auto drivers = drivers::make_drivers(plain, error);  // the sim for the joints
  ASSERT_EQ(error, "");
  auto owned = std::make_unique<ThreadedPanel>();
  ThreadedPanel& panel = *owned;
  drivers.push_back(drivers::DriverInstance{std::move(owned), {}});
  motion::MotionController motion(config);
  ASSERT_EQ(motion.start(std::move(drivers)), "");
  motion.reset_estop();
  motion.machine_on();
  ASSERT_TRUE(wait_for([&] { return motion.status().machine == motion::MachineState::on; }));
  panel.inputs = mpg_axis_bit(0) | bit(PanelInput::mpg_enable) | bit(PanelInput::mpg_step_100);
  panel.mpg = 5000;  // 500 mm at 200 mm/s: seconds of motion
  ASSERT_TRUE(wait_for([&] { return motion.status().panel.mpg_jogging; }));
  EXPECT_EQ(motion.jog_start(1, 10), "the panel's MPG is jogging");
  EXPECT_EQ(motion.jog_increment(2, 1, 10), "the panel's MPG is jogging");
  panel.inputs = 0;  // MPG disabled: the axis stops and the rest is dropped
  ASSERT_TRUE(wait_for([&] { return !motion.status().panel.mpg_jogging; }));
  EXPECT_LT(motion.status().commanded[0], 500);
  EXPECT_EQ(motion.jog_start(1, 10), "");
  motion.stop();
}

}  // namespace
}  // namespace cncd::test::panel
