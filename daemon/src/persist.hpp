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

// LinuxCNC's [TRAJ] POSITION_FILE: one joint position a line.
std::string format_position_file(const std::vector<double>& joints);
// Parses a position file. Returns nullopt and sets `error` ("FILE:LINE: what is wrong") when
// the file is corrupt; an absent file is not an error (returns an empty vector).
std::optional<std::vector<double>> read_position_file(const std::filesystem::path& path,
                                                      std::size_t joint_count, std::string& error);

}  // namespace cncd::daemon
