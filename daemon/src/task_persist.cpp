// The files the task keeps across runs: checking them at start, the joint positions at exit.
#include <filesystem>

#include <spdlog/spdlog.h>

#include "persist.hpp"
#include "task.hpp"

namespace cncd::daemon {

std::vector<JointRange> Task::joint_ranges() const {
  std::vector<JointRange> ranges;
  for (const auto& joint : config_.joints)
    ranges.push_back({joint.min_limit, joint.max_limit});
  return ranges;
}

std::string Task::load_files() {
  if (const auto& error = interp_->load_error()) {
    files_corrupt_ = true;
    // The parameter reader names the file and line itself.
    return error->message.rfind(error->file, 0) == 0 ? error->message : error->to_string();
  }
  if (config_.position_file.empty()) return "";
  std::string error;
  const auto joints = read_position_file(config_.position_file, joint_ranges(), error);
  if (!joints) {
    files_corrupt_ = true;
    return error;
  }
  if (!joints->empty()) motion_.set_start_positions(*joints);
  return "";
}

void Task::save_positions() {
  if (config_.position_file.empty() || !started_) return;
  const auto status = motion_.status();
  const std::vector<double> joints(
      status.joint_actual.begin(),
      status.joint_actual.begin() + static_cast<std::ptrdiff_t>(config_.joints.size()));
  if (const auto error = write_position_file(config_.position_file, joints, joint_ranges());
      !error.empty()) {
    events_.add("error", "positions", error);
    spdlog::error("{}", error);
  }
}

}  // namespace cncd::daemon
