// ServoLoop::publish(): the servo thread's status snapshot, once per period (RT).
#include "cncd/motion/servo_loop.hpp"

namespace cncd::motion {
namespace {
// Commanded positions within this of a soft limit count as standing on it (joint units).
constexpr double kAtSoftLimit = 1e-6;
}  // namespace

void ServoLoop::publish() noexcept {
  status_.sequence = status_.rt.cycles;
  status_.commanded = axis_pose_;
  status_.queued = path_.queued();
  status_.segments_done = path_.segments_done();
  status_.moves_done = path_.moves_done();
  status_.actions_done = path_.actions_done();
  status_.homed = joints_.homed;
  status_.spindle = io_.spindle();
  status_.io = io_.io();
  status_.wait = io_.wait();
  status_.sync = io_.sync();
  status_.input_result = io_.input_result();
  status_.input_waits = io_.input_waits();
  kins_->forward(joints_.feedback, status_.actual);
  status_.tcp = path_.tcp();
  if (kins_->has_tcp()) {
    status_.has_tcp = true;
    kins_->tcp_forward(status_.commanded, path_.tcp_tool_length(), status_.tip_commanded);
    kins_->tcp_forward(status_.actual, path_.tcp_tool_length(), status_.tip_actual);
  }
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    status_.joint_commanded[k] = joints_.command[k];
    status_.joint_actual[k] = joints_.feedback[k];
    const auto& fb = feedback_[k];
    const auto& joint = config_.joints[k];
    JointStatus& out = status_.joints[k];
    out.min_limit = fb.min_limit;
    out.max_limit = fb.max_limit;
    out.home_switch = fb.home_switch;
    out.enabled = commands_out_[k].enable;
    out.drive_fault = fb.fault;
    out.stale = fb.stale;
    const bool homed = joints_.homed[k];
    out.at_min_soft_limit = homed && joints_.command[k] <= joint.min_limit + kAtSoftLimit;
    out.at_max_soft_limit = homed && joints_.command[k] >= joint.max_limit - kAtSoftLimit;
  }
  published_.store(status_);
}

}  // namespace cncd::motion
