// Path execution, the servo loop's part that follows the planned path in time: segments taken
// from the planner's ring into a look-ahead window whose exit speeds a backward pass keeps
// up to date, and the window's front sampled once a period with trapezoidal or, under a jerk
// limit, S-curve profiles. It knows nothing of joints, drives or the machine's state: the
// servo loop tells it about holds and overrides and acts on the faults it reports. Every
// method but the constructor is RT (servo thread).
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/machine_io.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/spsc_ring.hpp"
#include "cncd/motion/status.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class PathExecutor {
 public:
  using SegmentRing = SpscRing<Segment, 1024>;
  // Why advance() stopped the path (it is dropped then, as by flush()).
  enum class Fault : std::uint8_t {
    none,
    joints_apart,  // a move would start while a joint stands apart from its axis
    off_path,      // a queued move does not start where the machine stands
  };
  struct Result {
    bool moved = false;  // the pose followed the path this period
    Fault fault = Fault::none;
  };

  // Non-RT. S-curve profiles when the config asks for a jerk limit the period can follow.
  PathExecutor(const config::MachineConfig& config, double period_s);
  // The path's jerk limit that S-curve profiles follow on `config`, 0 for trapezoidal profiles.
  static double jerk_limit(const config::MachineConfig& config, double period_s);

  // Producer: the planner (task thread). Consumer: the servo thread.
  SegmentRing& segments() noexcept { return segments_; }
  // Non-RT, before the first advance(): who does the actions and sets a segment's outputs
  // (none: actions are done at once, outputs ignored).
  void set_gate(ActionGate* gate) noexcept { gate_ = gate; }

  // One period of `dt` seconds along the path; `pose` (the axes) follows it. When a move
  // would start from rest while `joints_apart` is set, the path faults instead.
  CNCD_RT Result advance(double dt, AxisPose& pose, bool joints_apart) noexcept;
  // Drops every queued segment at once, counted as done (estop, drives off, a fault).
  CNCD_RT void flush() noexcept;
  // Controlled stop and the queue dropped once the path stands still (nothing when idle).
  CNCD_RT void abort() noexcept;
  CNCD_RT void pause() noexcept;
  CNCD_RT void resume() noexcept;
  // The feed and rapid override ratios, already clamped.
  CNCD_RT void set_overrides(double feed, double rapid) noexcept;

  // Path motion under way or waiting, in the look-ahead window or in the ring.
  CNCD_RT bool pending() const noexcept { return window_count_ > 0 || segments_.size() > 0; }
  // A segment is being executed: the path is not at rest between two periods.
  CNCD_RT bool active() const noexcept { return has_active_; }
  // The probing mode of the segment being executed (none when none is).
  // A move in step with the spindle is under way.
  CNCD_RT bool syncing() const noexcept {
    return has_active_ &&
           window_[static_cast<std::size_t>(head_seq_ % kWindow)].spindle_sync != SpindleSync::none;
  }
  CNCD_RT ProbeMode active_probe() const noexcept {
    return has_active_ ? window_[static_cast<std::size_t>(head_seq_ % kWindow)].probe
                       : ProbeMode::none;
  }
  CNCD_RT std::uint32_t queued() const noexcept {
    return static_cast<std::uint32_t>(segments_.size() + static_cast<std::size_t>(window_count_));
  }
  // What the last advance() left; the line stays that of the last segment executed.
  CNCD_RT double velocity() const noexcept { return velocity_; }
  CNCD_RT double distance_to_go() const noexcept { return distance_to_go_; }
  // Where the segment being executed ends; null between segments, in a dwell and at rest.
  CNCD_RT const AxisPose* segment_end() const noexcept {
    return has_segment_end_ ? &segment_end_ : nullptr;
  }
  CNCD_RT MotionState motion() const noexcept { return motion_; }
  CNCD_RT std::int32_t line() const noexcept { return line_; }
  // Whether the segment executed now, or the last one, was planned under TCP (Segment::tcp).
  CNCD_RT bool tcp() const noexcept { return tcp_; }
  // The tool length that segment was planned with (Segment::tool_length).
  CNCD_RT double tcp_tool_length() const noexcept { return tcp_tool_length_; }
  // Segments and programmed moves completed or dropped since the start.
  CNCD_RT std::uint64_t segments_done() const noexcept { return segments_done_; }
  CNCD_RT std::uint64_t moves_done() const noexcept { return moves_done_; }
  // Actions (Move::Kind::action) completed or dropped since the start.
  CNCD_RT std::uint64_t actions_done() const noexcept { return actions_done_; }
  // The path's jerk limit, 0 for trapezoidal profiles.
  CNCD_RT double jerk() const noexcept { return jerk_; }

 private:
  CNCD_RT Segment& window_at(std::uint64_t seq) noexcept {
    return window_[static_cast<std::size_t>(seq % kWindow)];
  }
  // Drops the path for `fault`.
  CNCD_RT void fail(Fault fault) noexcept;
  CNCD_RT bool starts_here(const Segment& segment, const AxisPose& pose) noexcept;  // false: failed
  CNCD_RT double speed_limit(const Segment& segment) const noexcept;  // with overrides and holds
  // Takes segments from the ring while the window holds less than the path needs to stop
  // from its fastest speed, and brings the exit speeds up to date, within this period's work
  // budget.
  CNCD_RT void fill_window() noexcept;
  // Continues the backward pass over the exit speeds for up to pass_budget_ steps.
  CNCD_RT void run_pass() noexcept;
  // The overrides or a hold changed: the override-dependent exit speeds are all recomputed.
  CNCD_RT void soft_limits_changed() noexcept;
  CNCD_RT void finish_front() noexcept;  // the window's first segment is done
  // The window's first segment starts: its outputs are set.
  CNCD_RT void activate(const Segment& segment) noexcept;
  CNCD_RT double window_floor_accel() noexcept;  // the smallest acceleration limit in the window
  // S-curve profiles (path_scurve.cpp): one period of path motion whose acceleration changes
  // by at most jerk_ per second, through as many segments as it covers. Spends all of `dt`.
  CNCD_RT void scurve_step(double& dt, AxisPose& pose) noexcept;
  // The speed limits ahead of the path's position into limits_, as far as the path, `ds`
  // further on at speed `v` and acceleration `a`, could need to slow down for them.
  CNCD_RT void gather_limits(double ds, double v, double a) noexcept;
  // Whether a step from `v_before`, `a_before` to speed `v` and acceleration `a`, `ds` further on,
  // keeps every limit gathered (the hard ones only when `soft` is false): those it passes, and
  // those ahead it can still slow down for; with `speeds_only`, the speeds alone and not the
  // coming segments' acceleration limits.
  CNCD_RT bool keeps_limits(double v_before, double a_before, double v, double a, double ds,
                            bool soft, bool speeds_only = false) const noexcept;
  // Whether a deceleration `a` at speed `v`, `ds` further on, can ease off to every coming
  // segment's own acceleration limit before reaching it.
  CNCD_RT bool eases_in_time(double v, double a, double ds) const noexcept;

  double period_s_;
  SegmentRing segments_;
  double feed_override_ = 1.0;
  double spindle_rps_seen_ = 0;  // the spindle speed the look-ahead's G95 speeds were set at
  int per_rev_in_window_ = 0;    // G95 segments in the look-ahead window
  double rapid_override_ = 1.0;
  // Look-ahead window: the segments taken from the ring, oldest first; the first is being
  // executed once has_active_. Segment sequence number n lives in window_[n % kWindow];
  // head_seq_ is the first's. exit_hard_ is the fastest speed at a segment's end from which
  // the path can still stop within the window under the axis limits alone, exit_soft_ the
  // same with the feed, the overrides and holds: the window's last segment always ends at
  // rest. Both are kept by an incremental backward pass.
  static constexpr int kWindow = 2048;
  static constexpr int kPassBudget = 4096;  // pass steps and ring pops per period
  static constexpr int kMaxPulls = 256;     // ring pops per period (each copies a segment)
  bool has_active_ = false;
  std::array<Segment, kWindow> window_{};
  std::array<double, kWindow> exit_hard_{};
  std::array<double, kWindow> exit_soft_{};
  std::uint64_t head_seq_ = 0;
  int window_count_ = 0;
  double window_length_ = 0;  // path length of the window's segments
  double stop_length_ = 0;    // longest stopping distance of the window's segments
  // The window's segments (dwells aside) whose acceleration limit is below that of every later
  // one, oldest first, in a ring indexed by the two counters: the first has the window's
  // smallest limit (S-curve profiles: how far ahead a limit can bind).
  std::array<std::uint64_t, kWindow> floor_seq_{};
  std::uint64_t floor_first_ = 0;
  std::uint64_t floor_end_ = 0;
  bool pass_active_ = false;
  std::uint64_t pass_seq_ = 0;    // next segment whose exit speeds the pass recomputes
  std::uint64_t pass_floor_ = 0;  // the pass goes at least this far back
  int pass_budget_ = 0;
  int pulls_left_ = 0;
  double path_s_ = 0;
  double path_v_ = 0;
  double path_a_ = 0;  // S-curve profiles only
  // S-curve profiles: the path's jerk limit (0: trapezoidal profiles) and the limits ahead.
  double jerk_ = 0;
  static constexpr double kMinRampPeriods = 20;
  struct SpeedLimit {
    double distance;  // from the path's position
    double soft;      // with the feed, the overrides and holds
    double hard;      // of the axes alone
    double accel;     // smallest path acceleration limit of the segments up to there
    double entry;     // the acceleration limit of the segment that starts there
    bool soft_on;     // whether the soft (hard) speed binds: no nearer limit is as low
    bool hard_on;
  };
  static constexpr int kMaxLimits = 1024;
  std::array<SpeedLimit, kMaxLimits> limits_{};
  int limit_count_ = 0;
  double cap_soft_ = 0, cap_hard_ = 0;  // the active segment's own speed limits
  double dwell_elapsed_s_ = 0;
  bool action_started_ = false;  // the active action has been asked once
  bool thread_chain_ = false;    // the segment done last was a thread move, run to its end
  ActionGate* gate_ = nullptr;
  bool pause_requested_ = false;
  bool abort_requested_ = false;
  Fault fault_ = Fault::none;  // of this period's advance()
  // What advance() reports.
  double velocity_ = 0;
  double distance_to_go_ = 0;
  AxisPose segment_end_{};
  bool has_segment_end_ = false;
  MotionState motion_ = MotionState::idle;
  std::int32_t line_ = 0;
  bool tcp_ = false;
  double tcp_tool_length_ = 0;
  std::uint64_t segments_done_ = 0;
  std::uint64_t moves_done_ = 0;
  std::uint64_t actions_done_ = 0;
};

}  // namespace cncd::motion
