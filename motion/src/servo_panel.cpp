// The panel's part of the servo loop: its inputs read, the MPG's counts turned into a jog of
// the selected axis (or dropped when it may not move), and the lights handed to the drivers.
#include <algorithm>
#include <cmath>

#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {
namespace {
constexpr auto kMpg = static_cast<std::size_t>(config::PanelCounter::mpg);
}  // namespace

void ServoLoop::advance_panel() noexcept {
  panel_.update(panel_in_, status_.panel);
  PanelStatus& panel = status_.panel;
  const std::int64_t counts = panel.counts[kMpg] - mpg_.seen;
  mpg_.seen = panel.counts[kMpg];
  settle_mpg();
  const std::uint32_t own = mpg_.moving >= 0 ? 1u << mpg_.moving : 0u;
  const int axis = panel.mpg_axis;
  // One hand on the machine: a client's jog (any axis) keeps the MPG still, and the MPG moves
  // one axis at a time. A move it let go of (a new selection, a stop) comes to rest before it
  // takes the wheel again, from where the axis then stands.
  const bool allowed = status_.machine == MachineState::on && !homing_.active() &&
                       !path_.pending() && panel_.mpg_enabled() && axis >= 0 && !mpg_.drop &&
                       !axis_joints_apart(axis) && (jog_.active_mask() & ~own) == 0 &&
                       !joint_jog_.active() && (mpg_.axis < 0 || mpg_.axis == axis) &&
                       (mpg_.moving < 0 || mpg_.moving == mpg_.axis);
  mpg_.drop = false;
  if (!allowed) {
    mpg_release();
  } else if (config_.panel.mpg_mode == config::PanelConfig::MpgMode::velocity) {
    mpg_velocity(axis, counts);
  } else {
    mpg_position(axis, counts);
  }
  settle_mpg();
}

void ServoLoop::mpg_release() noexcept {
  if (mpg_.axis < 0) return;
  if (mpg_.moving >= 0) jog_.stop(mpg_.moving);
  mpg_.axis = -1;
  mpg_.carry = 0;
  mpg_.detents = 0;
  mpg_.velocity = 0;
  mpg_.window_sum = 0;
  mpg_.at = 0;
  mpg_.ring.fill(0);
}

void ServoLoop::mpg_position(int axis, std::int64_t counts) noexcept {
  const auto k = static_cast<std::size_t>(axis);
  const double step = status_.panel.mpg_step;
  if (mpg_.axis != axis) {
    sync_axes_from_joints();  // the MPG starts from where the axis's joints stand
    mpg_.axis = axis;
    mpg_.base = axis_pose_[k];
    mpg_.detents = 0;
    mpg_.carry = 0;
    mpg_.step = step;
  }
  if (step != mpg_.step) {
    // Detents so far keep the distance they had; new ones move the new step.
    mpg_.base += static_cast<double>(mpg_.detents) * mpg_.step;
    mpg_.detents = 0;
    mpg_.step = step;
  }
  const std::int64_t per_detent = std::max(1, config_.panel.mpg_counts_per_detent);
  const std::int64_t total = mpg_.carry + counts;
  // Floor, not truncation: however the wheel went back and forth, the detents moved are
  // floor(counts / per detent), and the rest is carried.
  std::int64_t detents = total / per_detent;
  if (total % per_detent != 0 && total < 0) --detents;
  mpg_.carry = total - detents * per_detent;
  mpg_.detents += detents;
  // base + n x step, not a running sum: n detents land on the same place however they came.
  double target = mpg_.base + static_cast<double>(mpg_.detents) * mpg_.step;
  const auto& limits = config_.axes[k];
  if (axis_homed(axis)) {
    const double clipped = std::clamp(target, limits.min_limit, limits.max_limit);
    if (clipped != target) {
      // Detents beyond the limit are dropped: turning back moves off it at once.
      mpg_.base = clipped;
      mpg_.detents = 0;
      target = clipped;
    }
  }
  jog_.follow(axis, axis_pose_[k], target, limits.max_velocity);
  if ((jog_.active_mask() & (1u << axis)) != 0) mpg_.moving = axis;
}

void ServoLoop::mpg_velocity(int axis, std::int64_t counts) noexcept {
  const auto k = static_cast<std::size_t>(axis);
  if (mpg_.axis != axis) {
    sync_axes_from_joints();
    mpg_.axis = axis;
  }
  auto& slot = mpg_.ring[static_cast<std::size_t>(mpg_.at)];
  mpg_.window_sum -= slot;
  slot = static_cast<std::int32_t>(std::clamp<std::int64_t>(counts, -(1 << 30), 1 << 30));
  mpg_.window_sum += slot;
  mpg_.at = (mpg_.at + 1) % mpg_.window;
  mpg_.quiet = counts != 0 ? 0 : std::min(mpg_.quiet + 1, Mpg::kWindowMax);
  // The wheel has stopped once no count came for twice the time between its counts of late
  // (at least two periods), or for a whole window: a fast spin stops within a period or two.
  const std::int64_t recent = mpg_.window_sum < 0 ? -mpg_.window_sum : mpg_.window_sum;
  const std::int64_t gap = recent > 0 ? (2 * mpg_.window + recent - 1) / recent : mpg_.window;
  if (mpg_.window_sum == 0 || mpg_.quiet >= std::clamp<std::int64_t>(gap, 2, mpg_.window)) {
    // Stop at once; the counts that came before are never caught up.
    if (mpg_.velocity != 0 && mpg_.moving >= 0) jog_.stop(axis);
    mpg_.velocity = 0;
    if (mpg_.window_sum != 0 || counts != 0) mpg_.ring.fill(0);  // else already all 0
    mpg_.window_sum = 0;
    return;
  }
  const double window_s = mpg_.window * period_s_;
  const double per_detent = std::max(1, config_.panel.mpg_counts_per_detent);
  const double rate = static_cast<double>(mpg_.window_sum) / per_detent / window_s;
  const double max_velocity = config_.axes[k].max_velocity;
  const double velocity = std::clamp(rate * status_.panel.mpg_step, -max_velocity, max_velocity);
  if (velocity == mpg_.velocity) return;
  mpg_.velocity = velocity;
  // Refused at the soft limit it heads for: the axis stays there.
  if (jog_.start(axis, axis_pose_[k], velocity, axis_homed(axis)) != nullptr) return;
  if ((jog_.active_mask() & (1u << axis)) != 0) mpg_.moving = axis;
}

void ServoLoop::settle_mpg() noexcept {
  if (mpg_.moving >= 0 && (jog_.active_mask() & (1u << mpg_.moving)) == 0) mpg_.moving = -1;
  status_.panel.mpg_jogging = mpg_.moving >= 0;
}

std::uint32_t ServoLoop::panel_lights() const noexcept {
  std::uint32_t lights = lights_asked_;
  if (status_.machine == MachineState::estop || status_.fault.code != RtEvent::Code::none)
    lights |= 1u << static_cast<int>(config::PanelLight::red);
  return lights;
}

}  // namespace cncd::motion
