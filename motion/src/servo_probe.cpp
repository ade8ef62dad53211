// G38.2-G38.5 in the servo thread: the probe input is read once a period with the feedback; a
// probing move stops on the first period it trips (or loses contact), with the position of the
// machine in that period latched, and decelerates within the axes' limits.
#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {
namespace {

bool toward(ProbeMode mode) {
  return mode == ProbeMode::toward_or_error || mode == ProbeMode::toward;
}

}  // namespace

void ServoLoop::watch_probe() noexcept {
  status_.probe.contact = probe_input_;
  if (probe_mode_ == ProbeMode::none || probe_tripped_) return;
  const bool trips = toward(probe_mode_) ? probe_input_ : !probe_input_;
  if (!trips) return;
  // The input was read with this period's feedback: the machine was where the feedback says.
  probe_tripped_ = true;
  probe_position_ = status_.commanded;
  kins_->forward(joints_.feedback, probe_position_);
  path_.abort();
}

void ServoLoop::follow_probe() noexcept {
  if (probe_mode_ == ProbeMode::none) {
    const ProbeMode mode = path_.active_probe();
    if (mode == ProbeMode::none) return;
    // A probing move has just started: the probe must be as it is before contact.
    const bool wrong = toward(mode) ? probe_input_ : !probe_input_;
    if (wrong) {
      path_.flush();
      probe_error(toward(mode) ? RtEvent::Code::probe_tripped_at_start
                               : RtEvent::Code::probe_untripped_at_start);
      return;
    }
    probe_mode_ = mode;
    probe_tripped_ = false;
    status_.probe.armed = true;
    return;
  }
  if (path_.pending()) return;
  // The probing move is over: stopped after a trip, or at its end without one.
  const ProbeMode mode = probe_mode_;
  probe_mode_ = ProbeMode::none;
  status_.probe.armed = false;
  status_.probe.tripped = probe_tripped_;
  status_.probe.position = probe_tripped_ ? probe_position_ : axis_pose_;
  ++status_.probe.done;
  if (probe_tripped_) return;
  if (mode == ProbeMode::toward_or_error) probe_error(RtEvent::Code::probe_no_contact);
  if (mode == ProbeMode::away_or_error) probe_error(RtEvent::Code::probe_contact_kept);
}

void ServoLoop::disarm_probe() noexcept {
  probe_mode_ = ProbeMode::none;
  probe_tripped_ = false;
  status_.probe.armed = false;
}

void ServoLoop::probe_error(RtEvent::Code code) noexcept {
  // The program stops there; the machine stays on.
  RtEvent error;
  error.code = code;
  error.level = EventLevel::warning;
  status_.path_error = error;
  ++status_.path_errors;
  status_.motion = MotionState::idle;
  post(error);
}

}  // namespace cncd::motion
