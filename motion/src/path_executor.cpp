// Path execution: taking queued segments into the look-ahead window and sampling them in time.
#include "cncd/motion/path_executor.hpp"

#include <algorithm>
#include <cmath>

#include "profile.hpp"

namespace cncd::motion {

PathExecutor::PathExecutor(const config::MachineConfig& config, double period_s)
    : period_s_(period_s), jerk_(jerk_limit(config, period_s)) {}

double PathExecutor::jerk_limit(const config::MachineConfig& config, double period_s) {
  if (!config.scurve) return 0.0;
  // The acceleration must take at least kMinRampPeriods servo periods to build up on every
  // axis: steeper S-curves, which the period-by-period steps cannot follow within the axis
  // limits, are planned as trapezoids (cncd --check-config says so).
  double accel = 1e300;
  for (const auto& axis : config.axes) {
    if (axis.present && axis.max_acceleration > 0) accel = std::min(accel, axis.max_acceleration);
  }
  return config.max_linear_jerk * period_s * kMinRampPeriods <= accel ? config.max_linear_jerk
                                                                      : 0.0;
}

void PathExecutor::flush() noexcept {
  Segment dropped;
  if (syncing() && gate_ != nullptr) gate_->sync_ended();
  has_active_ = false;
  thread_chain_ = false;
  for (; window_count_ > 0; --window_count_, ++head_seq_) {
    ++segments_done_;
    moves_done_ += window_at(head_seq_).moves;
    if (window_at(head_seq_).action.kind != IoAction::Kind::none) ++actions_done_;
  }
  per_rev_in_window_ = 0;
  window_length_ = 0;
  stop_length_ = 0;
  floor_first_ = floor_end_ = 0;
  pass_active_ = false;
  while (segments_.pop(dropped)) {
    ++segments_done_;
    moves_done_ += dropped.moves;
    if (dropped.action.kind != IoAction::Kind::none) ++actions_done_;
  }
  path_s_ = 0;
  path_v_ = 0;
  path_a_ = 0;
  pause_requested_ = false;
  abort_requested_ = false;
}

void PathExecutor::fail(Fault fault) noexcept {
  fault_ = fault;
  flush();
  velocity_ = 0;
  distance_to_go_ = 0;
  motion_ = MotionState::idle;
}

void PathExecutor::abort() noexcept {
  if (pending()) abort_requested_ = true;
  soft_limits_changed();
}

void PathExecutor::pause() noexcept {
  pause_requested_ = true;
  soft_limits_changed();
}

void PathExecutor::resume() noexcept {
  pause_requested_ = false;
  soft_limits_changed();
}

void PathExecutor::set_overrides(double feed, double rapid) noexcept {
  feed_override_ = feed;
  rapid_override_ = rapid;
  soft_limits_changed();
}

bool PathExecutor::starts_here(const Segment& segment, const AxisPose& pose) noexcept {
  for (int i = 0; i < kAxes; ++i) {
    if (std::abs(segment.start[i] - pose[i]) > 1e-6) {
      // Following it would jump the motors to its start: the planner is out of step.
      fail(Fault::off_path);
      return false;
    }
  }
  return true;
}

double PathExecutor::speed_limit(const Segment& segment) const noexcept {
  if (pause_requested_ || abort_requested_) return 0.0;
  // Overrides only ever lower the speed below what the axes allow (a feed override above 1
  // raises the feed, never the axis limit); the profile decelerates within the segment's
  // acceleration when the limit drops under the current speed.
  if (segment.feed_per_rev > 0 && gate_ != nullptr) {
    // G95: per revolution of the spindle as it turns.
    return std::min(segment.axis_velocity,
                    segment.feed_per_rev * gate_->spindle_rps() * feed_override_);
  }
  if (segment.feed > 0) return std::min(segment.axis_velocity, segment.feed * feed_override_);
  return segment.axis_velocity * rapid_override_;
}

void PathExecutor::soft_limits_changed() noexcept {
  if (window_count_ < 2) return;
  pass_active_ = true;
  pass_seq_ = head_seq_ + static_cast<std::uint64_t>(window_count_) - 2;
  pass_floor_ = head_seq_;
}

void PathExecutor::run_pass() noexcept {
  // Backwards from the end: a segment's exit speed is what the junction allows (0 unless the
  // planner found the next segment tangent) and what the next segment can slow down from
  // to its own exit speed. Values only rise as the window grows, so a segment whose speeds
  // do not change ends the pass once the new segments are done.
  while (pass_active_ && pass_budget_ > 0) {
    if (pass_seq_ < head_seq_) {
      pass_active_ = false;
      break;
    }
    --pass_budget_;
    const std::uint64_t k = pass_seq_;
    const Segment& seg = window_at(k);
    const Segment& next = window_at(k + 1);
    const std::size_t i = static_cast<std::size_t>(k % kWindow);
    const std::size_t n = static_cast<std::size_t>((k + 1) % kWindow);
    double hard = 0;
    double soft = 0;
    if (seg.continuous && seg.kind != Segment::Kind::dwell && next.kind != Segment::Kind::dwell) {
      const double reach = 2.0 * next.max_acceleration * next.length;
      const double limit = std::min({seg.axis_velocity, next.axis_velocity, seg.junction_velocity});
      hard = std::min(limit, std::sqrt(exit_hard_[n] * exit_hard_[n] + reach));
      soft = std::min({limit, speed_limit(seg), speed_limit(next),
                       std::sqrt(exit_soft_[n] * exit_soft_[n] + reach)});
    }
    const bool same = hard == exit_hard_[i] && soft == exit_soft_[i];
    exit_hard_[i] = hard;
    exit_soft_[i] = soft;
    if ((same && k < pass_floor_) || k == head_seq_) {
      pass_active_ = false;
    } else {
      --pass_seq_;
    }
  }
}

void PathExecutor::fill_window() noexcept {
  for (;;) {
    run_pass();
    if (pass_active_) return;  // out of budget: the exit speeds so far are safe, only low
    if (window_count_ == 0) {
      window_length_ = 0;
      stop_length_ = 0;
    }
    const std::uint64_t first_new = head_seq_ + static_cast<std::uint64_t>(window_count_);
    // Eight times the longest stopping distance of a segment taken so far (one segment's
    // own acceleration can be well above those of the curves after it), so that the first
    // segment's exit speed is not held down by the window's end.
    while (pass_budget_ > 0 && pulls_left_ > 0 && window_count_ < kWindow &&
           (window_length_ < 8.0 * stop_length_ || window_count_ < 2)) {
      const std::uint64_t seq = head_seq_ + static_cast<std::uint64_t>(window_count_);
      Segment& seg = window_at(seq);
      if (!segments_.pop(seg)) break;
      --pass_budget_;
      --pulls_left_;
      if (seg.feed_per_rev > 0) ++per_rev_in_window_;
      exit_hard_[static_cast<std::size_t>(seq % kWindow)] = 0;
      exit_soft_[static_cast<std::size_t>(seq % kWindow)] = 0;
      ++window_count_;
      window_length_ += seg.length;
      if (seg.kind != Segment::Kind::dwell) {
        while (floor_end_ > floor_first_ &&
               window_at(floor_seq_[(floor_end_ - 1) % kWindow]).max_acceleration >=
                   seg.max_acceleration)
          --floor_end_;
        floor_seq_[floor_end_++ % kWindow] = seq;
      }
      if (seg.max_acceleration > 0) {
        // Under a jerk limit the acceleration takes a / j to build up and to fall back.
        const double v = seg.axis_velocity;
        const double a = seg.max_acceleration;
        stop_length_ = std::max(stop_length_, v * v / (2.0 * a) + (jerk_ > 0 ? v * a / jerk_ : 0));
      }
    }
    const std::uint64_t end = head_seq_ + static_cast<std::uint64_t>(window_count_);
    if (end == first_new) return;  // nothing taken
    if (first_new > head_seq_) {
      pass_active_ = true;
      pass_seq_ = end - 2;
      pass_floor_ = first_new - 1;
    } else if (window_count_ >= 2) {
      pass_active_ = true;
      pass_seq_ = end - 2;
      pass_floor_ = head_seq_;
    }
  }
}

void PathExecutor::activate(const Segment& segment) noexcept {
  tcp_ = segment.tcp;
  tcp_tool_length_ = segment.tool_length;
  if (gate_ != nullptr && segment.sync.any()) gate_->started(segment.sync);
}

void PathExecutor::finish_front() noexcept {
  const Segment& done = window_at(head_seq_);
  if (has_active_ && done.spindle_sync != SpindleSync::none && gate_ != nullptr)
    gate_->sync_ended();
  // The next move goes on along this one's helix if it is a thread move too.
  thread_chain_ = has_active_ && done.spindle_sync == SpindleSync::thread && !abort_requested_ &&
                  path_s_ >= done.length;
  ++segments_done_;
  moves_done_ += done.moves;
  if (done.action.kind != IoAction::Kind::none) ++actions_done_;
  if (done.feed_per_rev > 0) --per_rev_in_window_;
  window_length_ = std::max(0.0, window_length_ - done.length);
  if (floor_end_ > floor_first_ && floor_seq_[floor_first_ % kWindow] == head_seq_) ++floor_first_;
  ++head_seq_;
  --window_count_;
  has_active_ = false;
}

double PathExecutor::window_floor_accel() noexcept {
  return floor_end_ > floor_first_ ? window_at(floor_seq_[floor_first_ % kWindow]).max_acceleration
                                   : 0.0;
}

PathExecutor::Result PathExecutor::advance(double dt, AxisPose& pose, bool joints_apart) noexcept {
  fault_ = Fault::none;
  // G95 feeds follow the spindle: the look-ahead's speeds are brought up to date when its
  // speed has changed by more than 1 %.
  if (gate_ != nullptr && per_rev_in_window_ > 0) {
    const double rps = gate_->spindle_rps();
    if (std::abs(rps - spindle_rps_seen_) > 0.01 * std::max(rps, spindle_rps_seen_)) {
      spindle_rps_seen_ = rps;
      soft_limits_changed();
    }
  }
  // Joints and axes agree at the start of a period (not between two moves inside one).
  bool resting = !has_active_;
  bool moved = has_active_;
  pass_budget_ = kPassBudget;
  pulls_left_ = kMaxPulls;
  fill_window();
  // A period may finish one move and go on with the next: the profile's leftover time is
  // spent on the following segments, at the speed the junction allows, so short moves are not
  // slowed to one a period.
  while (dt > 0) {
    if (!has_active_) {
      if (window_count_ == 0) fill_window();
      if ((abort_requested_ && at_rest(path_v_)) || window_count_ == 0) break;
      // A move in step with the spindle cannot stop once under way: a hold there before it
      // starts holds before it.
      if (pause_requested_ && at_rest(path_v_) &&
          window_at(head_seq_).spindle_sync != SpindleSync::none)
        break;
      has_active_ = true;
      // Path motion drives every joint of an axis to the axis position: a gantry joint homed
      // apart from its twin (or to another HOME) would jump.
      if (resting && joints_apart) {
        fail(Fault::joints_apart);
        return {false, fault_};
      }
      if (!starts_here(window_at(head_seq_), pose)) return {false, fault_};
      resting = false;
      moved = true;
      path_s_ = 0;
      dwell_elapsed_s_ = 0;
      action_started_ = false;
      activate(window_at(head_seq_));
    }
    const Segment& active = window_at(head_seq_);
    line_ = active.line;
    bool done;
    if (active.spindle_sync != SpindleSync::none && gate_ != nullptr) {
      // The spindle's position, not time, moves the path; a pause waits for the move's end.
      double s = path_s_;
      double v = 0;
      done = gate_->follow(active, !action_started_, thread_chain_, feed_override_,
                           abort_requested_, dt, s, v);
      action_started_ = true;
      path_s_ = s;
      path_v_ = done ? 0.0 : v;
      path_a_ = 0;
      // Where it ends: back at the start (a tap), at the end (a thread), or where an abort
      // brought it to rest.
      pose = done && s >= active.length ? active.end : active.point_at(s);
      dt = 0;
    } else if (active.kind == Segment::Kind::dwell) {
      if (abort_requested_) {
        done = true;
      } else if (pause_requested_) {
        done = false;
        dt = 0;
      } else if (active.action.kind != IoAction::Kind::none) {
        done = gate_ == nullptr || gate_->run(active.action, !action_started_);
        action_started_ = true;
        if (!done) dt = 0;
      } else {
        const double left = active.dwell_s - dwell_elapsed_s_;
        done = left <= dt + 1e-12;
        dwell_elapsed_s_ += done ? left : dt;
        dt = done ? std::max(0.0, dt - left) : 0;
      }
      path_v_ = 0;
      path_a_ = 0;
    } else if (jerk_ > 0) {
      scurve_step(dt, pose);
      break;
    } else {
      const std::size_t i = static_cast<std::size_t>(head_seq_ % kWindow);
      done = advance_profile(path_s_, path_v_, active.length, speed_limit(active),
                             active.max_acceleration, std::min(exit_soft_[i], exit_hard_[i]), dt);
      pose = done ? active.end : active.point_at(path_s_);
      if (done && exit_hard_[i] <= 0) path_v_ = 0;
    }
    if (!done) break;
    finish_front();
  }
  velocity_ = path_v_;
  has_segment_end_ = has_active_ && window_at(head_seq_).kind != Segment::Kind::dwell;
  distance_to_go_ = has_segment_end_ ? window_at(head_seq_).length - path_s_ : 0.0;
  if (has_segment_end_) segment_end_ = window_at(head_seq_).end;
  if (abort_requested_ && at_rest(path_v_)) {
    flush();
    motion_ = MotionState::idle;
    return {moved, fault_};
  }
  if (!pending()) {
    motion_ = MotionState::idle;
  } else if (pause_requested_) {
    motion_ = at_rest(path_v_) && !syncing() ? MotionState::paused : MotionState::pausing;
  } else {
    motion_ = abort_requested_ ? MotionState::stopping : MotionState::moving;
  }
  return {moved, fault_};
}

}  // namespace cncd::motion
