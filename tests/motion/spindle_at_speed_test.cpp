// The at-speed gate against readings taken before the drive had the command, in virtual time.
// A drive gets each spindle command some periods late (a field bus, a base thread) and keeps
// reporting what it did before meanwhile: still forward at 1350 rpm, and at speed by its own
// bit, after M4. For every shape of feedback the drivers give (the sim spindle, a PWM spindle
// with and without an encoder, a Modbus VFD with an at-speed bit, a Modbus servo spindle), a
// feed after a change of speed or direction starts only once the drive turns at the new speed
// the new way.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/motion/machine_io.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::IoAction;
using motion::MotionState;
using motion::Move;

// The feedback shapes of the spindle drivers.
enum class Shape { sim, pwm, pwm_encoder, vfd_bit, servo_spindle };

const char* shape_name(Shape shape) {
  switch (shape) {
    case Shape::sim:
      return "sim";
    case Shape::pwm:
      return "gpio pwm";
    case Shape::pwm_encoder:
      return "gpio pwm with encoder";
    case Shape::vfd_bit:
      return "modbus vfd";
    case Shape::servo_spindle:
      return "modbus servo spindle";
  }
  return "?";
}

constexpr double kPeriodS = 0.001;

// A spindle drive that takes each command `lag` periods after it was written and ramps toward
// it at `acceleration` rpm/s, reporting every period what it does now, with the sequence of
// the command it has.
class LaggingSpindle final : public FakeDriver {
 public:
  LaggingSpindle(Shape shape, std::size_t lag, double acceleration)
      : FakeDriver("lagging"), shape_(shape), lag_(lag), acceleration_(acceleration) {}
  void write_io(const drivers::IoCommand& command) noexcept override {
    told_.push_back(command.spindle);  // test code
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override {
    drivers::SpindleCommand have;
    if (told_.size() > lag_) have = told_[told_.size() - 1 - lag_];
    target_ = !have.enable ? 0.0 : have.reverse ? -have.rpm : have.rpm;
    const double step = acceleration_ * kPeriodS;
    const double before = rpm_;
    rpm_ = std::abs(target_ - rpm_) <= step ? target_ : rpm_ + (target_ > rpm_ ? step : -step);
    revolutions_ += 0.5 * (before + rpm_) / 60.0 * kPeriodS;
    now_ns_ += 1'000'000;
    drivers::SpindleFeedback& fb = feedback.spindle;
    fb.present = true;
    fb.rpm = std::abs(rpm_);
    fb.acknowledged = have.sequence;
    const bool position =
        shape_ == Shape::sim || shape_ == Shape::pwm_encoder || shape_ == Shape::servo_spindle;
    fb.has_position = position;
    fb.revolutions = position ? revolutions_ : 0.0;
    fb.time_ns = shape_ == Shape::pwm_encoder || shape_ == Shape::servo_spindle ? now_ns_ : 0;
    if (shape_ == Shape::vfd_bit || shape_ == Shape::servo_spindle) {
      fb.has_at_speed = true;
      fb.at_speed = target_ != 0 && rpm_ == target_;
    }
    if (shape_ == Shape::servo_spindle)
      fb.command_delay_ns = static_cast<std::int64_t>(lag_) * 1'000'000;
  }
  // The shaft's signed speed now.
  double rpm() const { return rpm_; }

 private:
  Shape shape_;
  std::size_t lag_;
  double acceleration_;
  std::vector<drivers::SpindleCommand> told_;
  double target_ = 0;
  double rpm_ = 0;
  double revolutions_ = 0;
  std::int64_t now_ns_ = 1'000'000'000;
};

config::MachineConfig mill(double acceleration) {
  config::MachineConfig c = small_mill();
  c.spindle.present = true;
  c.spindle.driver = config::SpindleDriver::modbus;  // the test's drive stands in for it
  c.spindle.max_forward_velocity = 24000;
  c.spindle.max_reverse_velocity = 24000;
  c.spindle.acceleration = acceleration;
  c.spindle.at_speed_tolerance = 0.05;
  c.spindle.at_speed_timeout_s = 10;
  return c;
}

Move spindle_action(int direction, double rpm) {
  Move m;
  m.kind = Move::Kind::action;
  m.action.kind = IoAction::Kind::spindle;
  m.action.direction = static_cast<std::int8_t>(direction);
  m.action.rpm = rpm;
  return m;
}

Move wait_at_speed() {
  Move m;
  m.kind = Move::Kind::action;
  m.action.kind = IoAction::Kind::wait_at_speed;
  return m;
}

struct Case {
  Shape shape;
  int direction;  // of the second command (the first is M3 S1350)
  double rpm;
};

// M3 S1350, wait, a feed to X5; then the second command, wait, a feed to X10. Returns the
// drive's signed speed in the period the second feed starts (NaN: it never did).
double speed_when_the_second_feed_starts(const Case& c, std::size_t lag) {
  LaggingSpindle drive(c.shape, lag, 3000);
  VirtualMachine m(mill(3000), drivers::kCapHomeSwitch, nullptr, &drive);
  m.ready();
  m.queue(spindle_action(1, 1350));
  m.queue(wait_at_speed());
  m.queue(line_to(Move::Kind::feed, 5, 0, 0, 20));
  m.queue(spindle_action(c.direction, c.rpm));
  m.queue(wait_at_speed());
  m.queue(line_to(Move::Kind::feed, 10, 0, 0, 20));
  m.flush();
  for (int i = 0; i < 20'000; ++i) {
    m.cycles(1);
    const auto s = m.status();
    if (s.commanded[0] > 5 + 1e-9) return drive.rpm();
    if (s.motion == MotionState::idle && s.queued == 0) break;
  }
  return std::nan("");
}

TEST(SpindleAtSpeed, AFeedAfterAChangeWaitsForAReadingTakenAfterTheDriveHadIt) {
  // A reversal at the same speed (the old speed reads as the new one) and the M4 S800 after
  // M3 S1350 of a VFD that still turns forward at speed by its own bit.
  const std::vector<Case> cases = {
      {Shape::sim, -1, 1350},           {Shape::pwm, -1, 1350},
      {Shape::pwm_encoder, -1, 1350},   {Shape::vfd_bit, -1, 1350},
      {Shape::servo_spindle, -1, 1350}, {Shape::vfd_bit, -1, 800},
      {Shape::servo_spindle, -1, 800},  {Shape::sim, -1, 800},
  };
  for (const Case& c : cases) {
    for (const std::size_t lag : {std::size_t{1}, std::size_t{25}}) {
      SCOPED_TRACE(std::string(shape_name(c.shape)) + ", M" + (c.direction > 0 ? "3" : "4") + " S" +
                   std::to_string(c.rpm) + ", " + std::to_string(lag) + " periods late");
      const double rpm = speed_when_the_second_feed_starts(c, lag);
      const double want = c.direction * c.rpm;
      ASSERT_FALSE(std::isnan(rpm)) << "the second feed never started";
      EXPECT_NEAR(rpm, want, 0.05 * c.rpm);
    }
  }
}

TEST(SpindleAtSpeed, ASpeedChangeTheSameWayWaitsForTheNewSpeed) {
  for (const Shape shape : {Shape::sim, Shape::pwm, Shape::vfd_bit, Shape::servo_spindle}) {
    SCOPED_TRACE(shape_name(shape));
    // S1350 to S1400 is within 5 % of the old speed; to S2700 is not.
    for (const double rpm : {1400.0, 2700.0, 800.0}) {
      const double got = speed_when_the_second_feed_starts({shape, 1, rpm}, 25);
      ASSERT_FALSE(std::isnan(got));
      EXPECT_NEAR(got, rpm, 0.05 * rpm);
    }
  }
}

}  // namespace
}  // namespace cncd::test
