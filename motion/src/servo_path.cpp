// The path part of the servo loop: taking queued segments and sampling them in time.
#include "cncd/motion/servo_loop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "profile.hpp"

namespace cncd::motion {

bool ServoLoop::starts_here(const Segment& segment) noexcept {
  for (int i = 0; i < kAxes; ++i) {
    if (std::abs(segment.start[i] - axis_pose_[i]) > 1e-6) {
      // Following it would jump the motors to its start: the planner is out of step.
      latch_fault("a queued move does not start where the machine stands");
      return false;
    }
  }
  return true;
}

bool ServoLoop::joints_on_their_axes() noexcept {
  // Path motion drives every joint of an axis to the axis position: a gantry joint homed
  // apart from its twin (or to another HOME) would jump.
  for (int j = 0; j < joint_count_; ++j) {
    const int axis = joint_axis_[static_cast<std::size_t>(j)];
    if (axis < 0) continue;
    if (std::abs(joints_.command[static_cast<std::size_t>(j)] -
                 axis_pose_[static_cast<std::size_t>(axis)]) > 1e-6) {
      char text[120];
      std::snprintf(text, sizeof text,
                    "joint %d stands apart from axis %c: home the joints of an axis together, "
                    "to the same HOME",
                    j, config::kAxisLetters[static_cast<std::size_t>(axis)]);
      latch_fault(text);
      return false;
    }
  }
  return true;
}

namespace {

// Whether the path may go on at speed from `from` into `to`: G61/G64 and the same direction
// (within 1e-6 rad, so no axis changes speed by more than 1e-6 of the path speed at once).
bool tangent(const Segment& from, const Segment& to) noexcept {
  if (!from.continuous || from.kind == Segment::Kind::dwell || to.kind == Segment::Kind::dwell)
    return false;
  double dot = 0;
  for (int i = 0; i < kAxes; ++i)
    dot += from.end_direction[i] * to.start_direction[i];
  return dot > 1.0 - 5e-13;
}

}  // namespace

double ServoLoop::speed_limit(const Segment& segment) const noexcept {
  if (pause_requested_ || abort_requested_) return 0.0;
  // Overrides only ever lower the speed below what the axes allow (a feed override above 1
  // raises the feed, never the axis limit); the profile decelerates within the segment's
  // acceleration when the limit drops under the current speed.
  if (segment.feed > 0)
    return std::min(segment.axis_velocity, segment.feed * status_.feed_override);
  return segment.axis_velocity * status_.rapid_override;
}

void ServoLoop::refill_lookahead() noexcept {
  while (ahead_count_ < kLookAhead &&
         segments_.pop(ahead_[static_cast<std::size_t>((ahead_head_ + ahead_count_) % kLookAhead)]))
    ++ahead_count_;
}

void ServoLoop::exit_speeds(double& soft, double& hard) const noexcept {
  // Backwards from the window's last segment, which ends at rest: the machine can always
  // stop on the path within what it holds. The hard chain never depends on the overrides,
  // so lowering one never asks for more than the acceleration limit.
  soft = 0;
  hard = 0;
  for (int k = ahead_count_ - 1; k >= 0; --k) {
    const Segment& seg = ahead_[static_cast<std::size_t>((ahead_head_ + k) % kLookAhead)];
    const Segment& before =
        k == 0 ? active_ : ahead_[static_cast<std::size_t>((ahead_head_ + k - 1) % kLookAhead)];
    if (!tangent(before, seg)) {
      soft = 0;
      hard = 0;
      continue;
    }
    const double reach = 2.0 * seg.max_acceleration * seg.length;
    const double limit = std::min(before.axis_velocity, seg.axis_velocity);
    hard = std::min(limit, std::sqrt(hard * hard + reach));
    soft = std::min({limit, speed_limit(before), speed_limit(seg), std::sqrt(soft * soft + reach)});
  }
}

bool ServoLoop::advance_path(double dt) noexcept {
  // Joints and axes agree at the start of a period (not between two moves inside one).
  bool resting = !has_active_;
  bool moved = has_active_;
  refill_lookahead();
  // A period may finish one move and go on with the next: the profile's leftover time is
  // spent on the following segments, at the speed the junction allows, so short moves are not
  // slowed to one a period.
  while (dt > 0) {
    if (!has_active_) {
      if ((abort_requested_ && path_v_ <= 0) || ahead_count_ == 0) break;
      active_ = ahead_[static_cast<std::size_t>(ahead_head_)];
      ahead_head_ = (ahead_head_ + 1) % kLookAhead;
      --ahead_count_;
      refill_lookahead();
      has_active_ = true;
      if ((resting && !joints_on_their_axes()) || !starts_here(active_)) return false;
      resting = false;
      moved = true;
      path_s_ = 0;
      dwell_elapsed_s_ = 0;
    }
    status_.line = active_.line;
    bool done;
    if (active_.kind == Segment::Kind::dwell) {
      if (abort_requested_) {
        done = true;
      } else if (pause_requested_) {
        done = false;
        dt = 0;
      } else {
        const double left = active_.dwell_s - dwell_elapsed_s_;
        done = left <= dt + 1e-12;
        dwell_elapsed_s_ += done ? left : dt;
        dt = done ? std::max(0.0, dt - left) : 0;
      }
      path_v_ = 0;
    } else {
      double soft = 0;
      double hard = 0;
      exit_speeds(soft, hard);
      done = advance_profile(path_s_, path_v_, active_.length, speed_limit(active_),
                             active_.max_acceleration, std::min(soft, hard), dt);
      axis_pose_ = done ? active_.end : active_.point_at(path_s_);
      if (done && hard <= 0) path_v_ = 0;
    }
    if (!done) break;
    has_active_ = false;
    ++status_.segments_done;
  }
  status_.velocity = path_v_;
  status_.distance_to_go =
      has_active_ && active_.kind != Segment::Kind::dwell ? active_.length - path_s_ : 0.0;
  if (abort_requested_ && path_v_ == 0) {
    flush_queue();
    status_.motion = MotionState::idle;
    return moved;
  }
  if (!path_pending()) {
    status_.motion = MotionState::idle;
  } else if (pause_requested_) {
    status_.motion = path_v_ == 0 ? MotionState::paused : MotionState::pausing;
  } else {
    status_.motion = abort_requested_ ? MotionState::stopping : MotionState::moving;
  }
  return moved;
}

}  // namespace cncd::motion
