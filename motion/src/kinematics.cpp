#include "cncd/motion/kinematics.hpp"

#include "kins_modules.hpp"

namespace cncd::motion {

std::vector<RateLimit> axis_rate_limits(const config::MachineConfig& config) {
  std::vector<RateLimit> limits;
  for (int i = 0; i < kAxes; ++i) {
    const auto& axis = config.axes[static_cast<std::size_t>(i)];
    RateLimit limit;
    limit.terms[0] = {i, 1.0};
    limit.count = 1;
    limit.max_velocity = axis.max_velocity;
    limit.max_acceleration = axis.max_acceleration;
    limits.push_back(limit);
  }
  return limits;
}

RateLimit joint_rate_limit(const config::JointConfig& joint,
                           std::initializer_list<RateLimit::Term> terms) {
  RateLimit limit;
  for (const RateLimit::Term& term : terms)
    limit.terms[static_cast<std::size_t>(limit.count++)] = term;
  limit.max_velocity = joint.max_velocity;
  limit.max_acceleration = joint.max_acceleration;
  return limit;
}

std::unique_ptr<const Kinematics> make_kinematics(const config::MachineConfig& config) {
  // The loader refuses every other module.
  if (config.kinematics == "corexykins") return make_corexykins(config);
  if (config.kinematics == "xyzac-trt-kins" || config.kinematics == "xyzbc-trt-kins")
    return make_trtkins(config);
  return make_trivkins(config);
}

}  // namespace cncd::motion
