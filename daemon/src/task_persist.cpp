// The files the task keeps across runs: checking them at start, and the joint positions, kept
// up to date while the machine runs so that a crash or power loss loses little of them.
#include <filesystem>

#include <spdlog/spdlog.h>

#include "persist.hpp"
#include "start_checks.hpp"
#include "task.hpp"

namespace cncd::daemon {

std::vector<JointRange> Task::joint_ranges() const {
  return daemon::joint_ranges(config_);
}

namespace {
// A kill -9 or a power loss while moving loses at most this much of the joints' travel.
constexpr auto kPositionSaveInterval = std::chrono::seconds(2);
// After coming to rest the feedback may still settle (it answers the command of a period or
// more ago; drives lag): saved again this long after, and once more an interval later.
constexpr auto kSettleTime = std::chrono::milliseconds(250);

std::filesystem::path running_marker(const std::filesystem::path& position_file) {
  return position_file.string() + ".running";
}
}  // namespace

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
  if (!joints->empty()) {
    motion_.set_start_positions(*joints);
    // The marker outlived the last run: it ended without its final save (kill -9, a crash, a
    // power loss), and the file holds the positions saved last while it ran.
    std::error_code ec;
    position_restored_ =
        std::filesystem::exists(running_marker(config_.position_file), ec) ? "unclean" : "clean";
  }
  return "";
}

void Task::mark_running() {
  if (config_.position_file.empty() || files_corrupt_) return;
  const std::string error =
      atomic_write_file(running_marker(config_.position_file),
                        "cncd runs and keeps " + config_.position_file.filename().string() +
                            " up to date; an orderly shutdown removes this file\n");
  if (!error.empty()) {
    events_.add("warning", "positions", error + ": an unclean stop will not be recognised");
  }
}

std::string Task::write_positions(const motion::Status& status) {
  const std::vector<double> joints(
      status.joint_actual.begin(),
      status.joint_actual.begin() + static_cast<std::ptrdiff_t>(config_.joints.size()));
  if (auto problem = position_file_problem(config_.position_file, joints, joint_ranges());
      !problem.empty()) {
    return problem;
  }
  std::string text = format_position_file(joints);
  if (text == positions_written_) return "";
  std::string error = atomic_write_file(config_.position_file, text);
  if (error.empty()) positions_written_ = std::move(text);
  return error;
}

void Task::keep_positions(const motion::Status& status) {
  if (config_.position_file.empty() || !started_ || files_corrupt_) return;
  const auto now = std::chrono::steady_clock::now();
  const bool moving =
      status.motion != motion::MotionState::idle && status.motion != motion::MotionState::paused;
  bool due = false;
  if (moving) {
    due = now >= next_position_save_;
    settle_save_at_.reset();
  } else if (was_moving_) {
    // Come to rest: saved at once, and again when drives that lag have caught up.
    due = true;
    settle_save_at_ = now + kSettleTime;
    settle_saves_left_ = 2;
  } else if (settle_save_at_ && now >= *settle_save_at_) {
    due = true;
    if (--settle_saves_left_ > 0) {
      settle_save_at_ = now + kPositionSaveInterval;
    } else {
      settle_save_at_.reset();
    }
  }
  was_moving_ = moving;
  if (!due) return;
  next_position_save_ = now + kPositionSaveInterval;
  const std::string error = write_positions(status);
  if (error.empty()) {
    position_save_failing_ = false;
  } else if (!position_save_failing_) {
    // Once, not every two seconds, until it works again.
    position_save_failing_ = true;
    events_.add("error", "positions", error);
    spdlog::error("{}", error);
  }
}

void Task::save_positions() {
  if (config_.position_file.empty() || !started_) return;
  if (const auto error = write_positions(motion_.status()); !error.empty()) {
    events_.add("error", "positions", error);
    spdlog::error("{}", error);
    return;
  }
  // Written: the next start may call this stop clean.
  std::error_code ec;
  std::filesystem::remove(running_marker(config_.position_file), ec);
  if (ec)
    spdlog::error("cannot remove '{}': {}", running_marker(config_.position_file).string(),
                  ec.message());
}

}  // namespace cncd::daemon
