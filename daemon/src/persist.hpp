// Files that must survive a crash at any moment: written to a temporary file in the same
// directory, fsync'ed, renamed over the old one, and the directory fsync'ed.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cncd::daemon {

// Replaces `path` with `content` atomically. Returns "" or an error naming the file.
std::string atomic_write_file(const std::filesystem::path& path, const std::string& content);

// A joint's [JOINT_n] MIN_LIMIT and MAX_LIMIT (joint units).
struct JointRange {
  double min = -1e99;
  double max = 1e99;
};

// A position file may hold a joint this far (as a share of its travel) beyond a limit: an
// unhomed machine may have been jogged a little past them.
inline constexpr double kPositionMarginShare = 0.1;

// "" when joint `joint` may stand at `value` as far as a position file goes: finite, and at
// most kPositionMarginShare of its travel outside its limits; else why not.
std::string position_problem(int joint, double value, const JointRange& range);

// LinuxCNC's [TRAJ] POSITION_FILE: one joint position a line.
std::string format_position_file(const std::vector<double>& joints);
// "" when every position passes position_problem(), else an error naming the file and saying
// that it is not written.
std::string position_file_problem(const std::filesystem::path& path,
                                  const std::vector<double>& joints,
                                  const std::vector<JointRange>& ranges);
// Writes the file atomically when position_file_problem() finds nothing; otherwise leaves the
// old file alone. Returns "" or an error naming the file.
std::string write_position_file(const std::filesystem::path& path,
                                const std::vector<double>& joints,
                                const std::vector<JointRange>& ranges);
// Parses a position file for a machine with one joint per entry of `ranges`. Returns nullopt
// and sets `error` ("FILE:LINE: what is wrong") when the file is corrupt or a position fails
// position_problem(); an absent file is not an error (returns an empty vector).
std::optional<std::vector<double>> read_position_file(const std::filesystem::path& path,
                                                      const std::vector<JointRange>& ranges,
                                                      std::string& error);

}  // namespace cncd::daemon
