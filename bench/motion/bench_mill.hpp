// The simulated three-axis mill the servo benches run: X, Y and Z of +-500 mm at 200 mm/s and
// 2000 mm/s^2, a joint each, a 1 ms period.
#pragma once

#include <cstddef>

#include "cncd/config/machine_config.hpp"

namespace cncd::bench {

inline config::MachineConfig three_axis_mill() {
  config::MachineConfig c;
  c.servo_period_ns = 1'000'000;
  c.coordinates = "XYZ";
  c.joint_count = 3;
  c.max_linear_velocity = 200;
  for (int i = 0; i < 3; ++i) {
    auto& axis = c.axes[static_cast<std::size_t>(i)];
    axis.present = true;
    axis.min_limit = -500;
    axis.max_limit = 500;
    axis.max_velocity = 200;
    axis.max_acceleration = 2000;
    config::JointConfig joint;
    joint.axis = "XYZ"[i];
    joint.max_velocity = 200;
    joint.max_acceleration = 2000;
    joint.home_sequence = 0;
    c.joints.push_back(joint);
  }
  return c;
}

}  // namespace cncd::bench
