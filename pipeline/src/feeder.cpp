#include "cncd/pipeline/feeder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <variant>

#include "cncd/motion/kinematics.hpp"
#include "cncd/motion/planner.hpp"
#include "cncd/pipeline/machine.hpp"

namespace cncd::pipeline {
namespace {

// The motion's probe mode of a G38 kind, in interp::ProbeKind's order (G38.2 .. G38.5).
motion::ProbeMode probe_mode(interp::ProbeKind kind) {
  constexpr motion::ProbeMode kModes[] = {
      motion::ProbeMode::toward_or_error, motion::ProbeMode::toward,
      motion::ProbeMode::away_or_error, motion::ProbeMode::away};
  return kModes[static_cast<std::size_t>(kind)];
}

}  // namespace

void ProgramFeeder::start_program(const motion::AxisPose* at, bool mdi) {
  pending_.clear();
  moves_queued_ = actions_queued_ = 0;
  approach_moves_ = 0;
  stop_seen_ = false;
  input_wait_seen_ = false;
  probe_seen_ = false;
  unsupported_.reset();
  if (!mdi) {
    per_revolution_ = false;
    css_max_rpm_ = 0;
    tcp_ = false;
  }
  per_rev_ = 0;
  holds_.clear();
  sync_ = {};
  need_at_speed_ = false;
  end_ = at != nullptr ? *at : motion::AxisPose{};
}

motion::IoAction ProgramFeeder::spindle_action() const {
  motion::IoAction a;
  a.kind = motion::IoAction::Kind::spindle;
  a.direction = static_cast<std::int8_t>(spindle_direction_);
  a.rpm = spindle_speed_;
  if (css_max_rpm_ > 0) {
    // G96: S is metres (G21) or feet (G20) per minute at the tool, X0 the spindle's axis.
    constexpr double kTwoPi = 6.283185307179586;
    const double per_s = tracker_.program_units() == interp::Units::inches ? 12.0 : 1000.0;
    a.css_numerator = spindle_speed_ * per_s * tracker_.length_factor() / kTwoPi;
    a.css_max_rpm = css_max_rpm_;
    a.css_x_origin = tracker_.machine_pose(interp::Pose{})[0];
  }
  return a;
}

void ProgramFeeder::check_speed(int line) {
  if (machine_ == nullptr || !on_warning_ || spindle_direction_ == 0 || spindle_speed_ <= 0 ||
      css_max_rpm_ > 0)
    return;
  const config::SpindleConfig& sp = machine_->spindle;
  if (!sp.present || sp.driver == config::SpindleDriver::none) return;
  const bool reverse = spindle_direction_ < 0;
  const double lo = reverse ? sp.min_reverse_velocity : sp.min_forward_velocity;
  const double hi = reverse ? sp.max_reverse_velocity : sp.max_forward_velocity;
  if ((spindle_speed_ >= lo && spindle_speed_ <= hi) || spindle_speed_ == warned_rpm_) return;
  warned_rpm_ = spindle_speed_;
  const bool above = spindle_speed_ > hi;
  const std::string key =
      std::string(above ? "MAX_" : "MIN_") + (reverse ? "REVERSE" : "FORWARD") + "_VELOCITY";
  char text[200];
  std::snprintf(text, sizeof text, "S%g is %s [SPINDLE_0] %s %g: the spindle turns at %g rpm",
                spindle_speed_, above ? "above" : "below", key.c_str(), above ? hi : lo,
                above ? hi : lo);
  on_warning_(line, text);
}

void ProgramFeeder::add_action(const motion::IoAction& action, int line) {
  motion::Move move;
  move.kind = motion::Move::Kind::action;
  move.action = action;
  move.line = line;
  move.path_mode = path_mode_;
  pending_.push_back(move);
}

void ProgramFeeder::begin_move(motion::Move& next, int line) {
  // A tap brings the spindle to rest before it starts: no need to wait for its speed.
  if (next.kind != motion::Move::Kind::traverse && next.spindle_sync != motion::SpindleSync::tap &&
      need_at_speed_) {
    add_action({.kind = motion::IoAction::Kind::wait_at_speed}, line);
    need_at_speed_ = false;
  }
  if (!unsupported_ && machine_ != nullptr) {
    if (auto why = axis_missing(*machine_, end_, next.end)) unsupported_ = Unsupported{line, *why};
  }
  if (!unsupported_ && tcp_) {
    if (auto why = motion::tcp_refusal(next, end_)) unsupported_ = Unsupported{line, *why};
  }
  next.sync = sync_;
  sync_ = {};
  next.tcp = tcp_;
  next.tool_length = tool_length_;
  end_ = next.end;
}

void ProgramFeeder::emit(const interp::CanonCommand& command) {
  namespace in = interp;
  const in::CanonCommand m = tracker_.to_machine(command);
  if (const auto* spline = std::get_if<in::NurbsFeed>(&m.op)) {
    queue_spline(*spline, m.line);
    return;
  }
  motion::Move move;
  move.line = m.line;
  using Action = motion::IoAction;
  // Spindle, coolant and output events are actions the servo thread does where the path
  // rests; a feed move after the spindle starts or changes speed waits until it is at speed.
  auto spindle = [&](int direction) {
    spindle_direction_ = direction;
    check_speed(m.line);
    add_action(spindle_action(), m.line);
    need_at_speed_ = direction != 0;
    return false;
  };
  auto coolant = [&](bool& flag, bool on) {
    flag = on;
    add_action({.kind = Action::Kind::coolant, .flood = flood_, .mist = mist_}, m.line);
    return false;
  };
  auto hold = [&](HoldInfo info) { add_hold(std::move(info), m.line); };
  auto tool_change = [&](int number) {
    queue_tool_change(number, m.line, tool_);
    return false;
  };
  auto moving = [&](motion::Move& next) { begin_move(next, m.line); };
  auto stop = [&] {
    stop_seen_ = true;
    return false;
  };
  const bool queued = std::visit(
      in::Overloaded{
          [&](const in::StraightTraverse& c) {
            move.kind = motion::Move::Kind::traverse;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            moving(move);
            return true;
          },
          [&](const in::StraightFeed& c) {
            move.kind = motion::Move::Kind::feed;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            if (per_rev_ > 0) {
              // G33: the path rests before the thread, which runs alone.
              add_stop_point();
              move.spindle_sync = motion::SpindleSync::thread;
              move.per_rev = per_rev_;
              move.feed = per_rev_ * nominal_rpm(end_[0]) / 60.0;
              if (!unsupported_ && machine_ != nullptr) {
                // G96 turns fastest at the end nearer the spindle's axis.
                const double rpm = std::max(nominal_rpm(end_[0]), nominal_rpm(move.end[0]));
                // Under TCP the joints move along the line the tip's makes in their space.
                motion::AxisPose from = end_, to = move.end;
                if (tcp_) {
                  kins_->tcp_inverse(end_, tool_length_, from);
                  kins_->tcp_inverse(move.end, tool_length_, to);
                }
                if (auto why = thread_too_fast(*machine_, from, to, per_rev_, rpm,
                                               spindle_direction_, spindle_speed_))
                  unsupported_ = Unsupported{m.line, *why};
              }
            } else {
              move.feed = feed_per_second();
              if (per_revolution_) move.feed_per_rev = tracker_.feed_per_minute();
            }
            moving(move);
            return true;
          },
          [&](const in::RigidTap& c) {
            if (!unsupported_ && machine_ != nullptr) {
              if (auto why = spindle_cannot_reverse(*machine_))
                unsupported_ = Unsupported{m.line, *why};
            }
            add_stop_point();
            move.kind = motion::Move::Kind::feed;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            move.spindle_sync = motion::SpindleSync::tap;
            move.per_rev = per_rev_;
            move.retract_scale = c.scale;
            move.feed = per_rev_ * nominal_rpm(end_[0]) / 60.0;
            const motion::AxisPose start = end_;
            moving(move);
            // The tap ends where it started, the spindle turning as before: a feed move after
            // it waits until it is back at speed.
            end_ = start;
            need_at_speed_ = spindle_direction_ != 0;
            return true;
          },
          [&](const in::ArcFeed& c) {
            move.kind = motion::Move::Kind::arc;
            const in::Pose end = c.end();
            std::copy(end.begin(), end.end(), move.end.begin());
            move.feed = feed_per_second();
            if (per_revolution_) move.feed_per_rev = tracker_.feed_per_minute();
            const in::PlaneAxes axes = in::plane_axes(c.plane);
            move.plane_axes = {static_cast<int>(axes.first), static_cast<int>(axes.second),
                               static_cast<int>(axes.normal)};
            move.center_first = c.first_axis;
            move.center_second = c.second_axis;
            move.turns = c.rotation;
            moving(move);
            return true;
          },
          [&](const in::StraightProbe& c) {
            // The path comes to rest before a probing move, which runs alone.
            add_stop_point();
            move.kind = motion::Move::Kind::feed;
            std::copy(c.end.begin(), c.end.end(), move.end.begin());
            move.feed = feed_per_second();
            move.probe = probe_mode(c.kind);
            moving(move);
            probe_seen_ = true;
            return true;
          },
          [&](const in::SetTcp& c) {
            switch_tcp(c.on, m.line);
            return false;
          },
          [&](const in::UseToolLengthOffset&) {
            change_tool_length(m.line);
            return false;
          },
          [&](const in::SetFeedMode& c) {
            per_revolution_ = c.mode == in::FeedRateMode::per_revolution;
            return false;
          },
          [&](const in::SetSpindleMode& c) {
            // G96 D (1e30 without D) or G97: the spindle takes the mode at once, S with it.
            css_max_rpm_ = std::isfinite(c.css_max_rpm) && c.css_max_rpm > 0 ? c.css_max_rpm : 0.0;
            add_action(spindle_action(), m.line);
            need_at_speed_ = spindle_direction_ != 0;
            return false;
          },
          [&](const in::StartSpeedFeedSynch& c) {
            per_rev_ = c.feed_per_rev;
            if (!unsupported_ && machine_ != nullptr) {
              if (auto why = spindle_position_missing(*machine_))
                unsupported_ = Unsupported{m.line, *why};
            }
            return false;
          },
          [&](const in::OrientSpindle& c) {
            if (!unsupported_ && machine_ != nullptr) {
              if (auto why = spindle_cannot_orient(*machine_))
                unsupported_ = Unsupported{m.line, *why};
            }
            // The spindle stops for it, and the program goes on once it is oriented.
            spindle_direction_ = 0;
            need_at_speed_ = false;
            add_action({.kind = Action::Kind::orient_spindle,
                        .mode = static_cast<std::int8_t>(c.mode),
                        .value = c.angle_deg,
                        .timeout_s = kOrientTimeoutS},
                       m.line);
            return false;
          },
          [&](const in::WaitOrientSpindle& c) {
            // M19 R.. Q..: the orientation just queued waits at most Q seconds.
            if (!pending_.empty() && pending_.back().line == m.line &&
                pending_.back().kind == motion::Move::Kind::action &&
                pending_.back().action.kind == Action::Kind::orient_spindle) {
              pending_.back().action.timeout_s = c.timeout_s;
              return false;
            }
            add_action({.kind = Action::Kind::wait_orient, .timeout_s = c.timeout_s}, m.line);
            return false;
          },
          [&](const in::StopSpeedFeedSynch&) {
            per_rev_ = 0;
            return false;
          },
          [&](const in::Dwell& c) {
            move.kind = motion::Move::Kind::dwell;
            move.dwell_s = c.seconds;
            return true;
          },
          [&](const in::SetMotionControlMode& c) {
            // G61.1 stops after every move, G61 only where the path turns (and, as canned
            // cycles run in G61, where a traverse meets a feed move), G64 blends corners
            // within P.
            path_mode_ = c.mode == in::MotionMode::exact_stop   ? motion::Move::PathMode::exact_stop
                         : c.mode == in::MotionMode::exact_path ? motion::Move::PathMode::exact_path
                                                                : motion::Move::PathMode::blend;
            tolerance_ = std::max(0.0, c.tolerance * tracker_.length_factor());
            return false;
          },
          [&](const in::SetNaivecamTolerance& c) {
            merge_tolerance_ = std::max(0.0, c.tolerance * tracker_.length_factor());
            return false;
          },
          [&](const in::ProgramStop&) { return stop(); },
          [&](const in::OptionalProgramStop&) { return optional_stop_ && stop(); },
          [&](const in::StartSpindleClockwise&) { return spindle(1); },
          [&](const in::StartSpindleCounterclockwise&) { return spindle(-1); },
          [&](const in::StopSpindleTurning&) { return spindle(0); },
          [&](const in::SetSpindleSpeed& c) {
            spindle_speed_ = c.rpm;
            check_speed(m.line);
            add_action(spindle_action(), m.line);
            need_at_speed_ = spindle_direction_ != 0;
            return false;
          },
          [&](const in::SetSpindleOverrideEnable& c) {
            add_action({.kind = Action::Kind::spindle_override_enable, .on = c.on}, m.line);
            return false;
          },
          [&](const in::SetOutputBit& c) {
            const std::uint32_t bit =
                c.index >= 0 && c.index < motion::kMaxDigitalIo ? 1u << c.index : 0u;
            if (c.motion) {
              sync_.set = c.on ? sync_.set | bit : sync_.set & ~bit;
              sync_.clear = c.on ? sync_.clear & ~bit : sync_.clear | bit;
            } else {
              add_action({.kind = Action::Kind::digital_output,
                          .on = c.on,
                          .index = static_cast<std::int16_t>(c.index)},
                         m.line);
            }
            return false;
          },
          [&](const in::SetOutputValue& c) {
            if (c.motion) {
              if (c.index >= 0 && c.index < motion::kMaxAnalogIo) {
                sync_.analog[static_cast<std::size_t>(c.index)] = c.value;
                sync_.analog_mask |= 1u << c.index;
              }
            } else {
              add_action({.kind = Action::Kind::analog_output,
                          .index = static_cast<std::int16_t>(c.index),
                          .value = c.value},
                         m.line);
            }
            return false;
          },
          [&](const in::WaitInput& c) {
            add_action({.kind = Action::Kind::wait_input,
                        .digital = c.digital,
                        .mode = static_cast<std::int8_t>(c.mode),
                        .index = static_cast<std::int16_t>(c.index),
                        .timeout_s = c.timeout_s},
                       m.line);
            input_wait_seen_ = true;
            return false;
          },
          [&](const in::UserMCode& c) {
            HoldInfo info;
            info.kind = Action::Hold::user_m;
            info.user = c;
            hold(std::move(info));
            return false;
          },
          [&](const in::MistOn&) { return coolant(mist_, true); },
          [&](const in::MistOff&) { return coolant(mist_, false); },
          [&](const in::FloodOn&) { return coolant(flood_, true); },
          [&](const in::FloodOff&) { return coolant(flood_, false); },
          [&](const in::ChangeTool& c) { return tool_change(c.tool); },
          [&](const in::ChangeToolNumber& c) {
            tool_ = c.tool;  // M61: the tool is already in the spindle
            return false;
          },
          [&](const in::Message& c) {
            if (on_message_) on_message_(m.line, c.text);
            return false;
          },
          // No pallet changer to drive: M60 pauses through the ProgramStop that follows it;
          // M30 ends the program, as M2 does.
          [](const auto&) { return false; },
      },
      m.op);
  if (!queued) return;
  // A probing move stops where the probe trips, and a move in step with the spindle starts and
  // ends at rest: nothing may blend into or out of them.
  const bool alone =
      move.probe != motion::ProbeMode::none || move.spindle_sync != motion::SpindleSync::none;
  move.path_mode = alone ? motion::Move::PathMode::exact_stop : path_mode_;
  move.tolerance = tolerance_;
  move.merge_tolerance =
      !alone && path_mode_ == motion::Move::PathMode::blend ? merge_tolerance_ : 0.0;
  pending_.push_back(move);
}

double ProgramFeeder::nominal_rpm(double x) const {
  if (css_max_rpm_ <= 0) return spindle_speed_;
  const motion::IoAction a = spindle_action();
  const double radius = std::abs(x - a.css_x_origin);
  double rpm = radius > 1e-9 ? std::min(a.css_max_rpm, a.css_numerator / radius) : a.css_max_rpm;
  if (machine_ != nullptr && machine_->spindle.present)
    rpm = std::min(rpm, machine_->spindle.max_forward_velocity);
  return rpm;
}

double ProgramFeeder::feed_per_second() const {
  const double f = tracker_.feed_per_minute();
  // G95: F per revolution at the programmed speed (the interpreter refuses it at S 0).
  return (per_revolution_ ? f * nominal_rpm(end_[0]) : f) / 60.0;
}

Drained ProgramFeeder::drain(motion::MoveQueue& queue) {
  using Push = motion::MoveQueue::Push;
  while (!pending_.empty()) {
    if (!queue.ready()) return {Push::full, 0};
    const motion::Move& move = pending_.front();
    if (stop_point(move)) {
      queue.end_path();
      pending_.pop_front();
      continue;
    }
    const Push result = queue.push_move(move);
    if (result != Push::accepted) return {result, move.line};
    ++(move.kind == motion::Move::Kind::action ? actions_queued_ : moves_queued_);
    pending_.pop_front();
  }
  return {};
}

void ProgramFeeder::add_stop_point() {
  if (!pending_.empty() && stop_point(pending_.back())) return;
  motion::Move stop;
  stop.kind = motion::Move::Kind::dwell;
  stop.dwell_s = 0;
  pending_.push_back(stop);
}

}  // namespace cncd::pipeline
