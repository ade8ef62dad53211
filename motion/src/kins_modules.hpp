// The kinematics modules make_kinematics() chooses from, one file each, and what they share.
#pragma once

#include <memory>
#include <vector>

#include "cncd/motion/kinematics.hpp"

namespace cncd::motion {

// trivkins (kins_trivial.cpp), corexykins (kins_corexy.cpp), xyzac-trt-kins and
// xyzbc-trt-kins (kins_trt.cpp).
std::unique_ptr<const Kinematics> make_trivkins(const config::MachineConfig& config);
std::unique_ptr<const Kinematics> make_corexykins(const config::MachineConfig& config);
std::unique_ptr<const Kinematics> make_trtkins(const config::MachineConfig& config);

// Every axis's own limits, one bound an axis in axis order (those the machine lacks too: no
// move ever has a share along them).
std::vector<RateLimit> axis_rate_limits(const config::MachineConfig& config);
// A joint's bound: the joint moves by sum coefficient x axis, within its own limits.
RateLimit joint_rate_limit(const config::JointConfig& joint,
                           std::initializer_list<RateLimit::Term> terms);

}  // namespace cncd::motion
