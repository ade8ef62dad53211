#include "persist.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "cncd/config/number_text.hpp"

namespace cncd::daemon {
namespace {

std::string os_error(const std::string& what, const std::filesystem::path& path) {
  return what + " '" + path.string() + "': " + std::strerror(errno);
}

}  // namespace

std::string atomic_write_file(const std::filesystem::path& path, const std::string& content) {
  const auto dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string temp = (dir / ("." + path.filename().string() + ".XXXXXX")).string();
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return os_error("cannot create a temporary file next to", path);
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string error = os_error("cannot write", temp);
      ::close(fd);
      ::unlink(temp.c_str());
      return error;
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fchmod(fd, 0644) != 0 || ::fsync(fd) != 0) {
    const std::string error = os_error("cannot flush", temp);
    ::close(fd);
    ::unlink(temp.c_str());
    return error;
  }
  // Some file systems (NFS) report a failed write only at close.
  if (::close(fd) != 0) {
    const std::string error = os_error("cannot write", temp);
    ::unlink(temp.c_str());
    return error;
  }
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string error = os_error("cannot replace", path);
    ::unlink(temp.c_str());
    return error;
  }
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return "";
}

std::string position_problem(int joint, double value, const JointRange& range) {
  const std::string where =
      "joint " + std::to_string(joint) + " position " + config::format_number(value);
  if (!std::isfinite(value)) return where + " is not a finite number";
  const double margin = kPositionMarginShare * (range.max - range.min);
  if (value >= range.min - margin && value <= range.max + margin) return "";
  return where + " is outside its limits [" + config::format_number(range.min) + ", " +
         config::format_number(range.max) + "] by more than 10 % of its travel";
}

std::string position_file_problem(const std::filesystem::path& path,
                                  const std::vector<double>& joints,
                                  const std::vector<JointRange>& ranges) {
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const std::string problem = position_problem(static_cast<int>(j), joints[j],
                                                 j < ranges.size() ? ranges[j] : JointRange{});
    if (!problem.empty()) {
      return path.string() + ": not written (the positions saved before stay): " + problem;
    }
  }
  return "";
}

std::string write_position_file(const std::filesystem::path& path,
                                const std::vector<double>& joints,
                                const std::vector<JointRange>& ranges) {
  if (auto problem = position_file_problem(path, joints, ranges); !problem.empty()) return problem;
  return atomic_write_file(path, format_position_file(joints));
}

std::string format_position_file(const std::vector<double>& joints) {
  std::string out;
  char line[64];
  for (const double value : joints) {
    std::snprintf(line, sizeof line, "%.9f\n", value);
    out += line;
  }
  return out;
}

std::optional<std::vector<double>> read_position_file(const std::filesystem::path& path,
                                                      const std::vector<JointRange>& ranges,
                                                      std::string& error) {
  const std::size_t joint_count = ranges.size();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::vector<double>{};
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = os_error("cannot read", path);
    return std::nullopt;
  }
  std::vector<double> joints;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.size() > 256) {
      error = path.string() + ":" + std::to_string(number) + ": line too long";
      return std::nullopt;
    }
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const auto last = line.find_last_not_of(" \t\r");
    double value = 0;
    const char* begin = line.data() + first;
    const char* end = line.data() + last + 1;
    const auto [ptr, ec2] = std::from_chars(begin, end, value);
    if (ec2 != std::errc() || ptr != end || !std::isfinite(value)) {
      error = path.string() + ":" + std::to_string(number) + ": '" + line.substr(first) +
              "' is not a position";
      return std::nullopt;
    }
    if (joints.size() < joint_count) {
      const std::string problem =
          position_problem(static_cast<int>(joints.size()), value, ranges[joints.size()]);
      if (!problem.empty()) {
        error = path.string() + ":" + std::to_string(number) + ": " + problem;
        return std::nullopt;
      }
    }
    joints.push_back(value);
  }
  if (joints.size() != joint_count) {
    error = path.string() + ": holds " + std::to_string(joints.size()) +
            " positions, the machine has " + std::to_string(joint_count) + " joints";
    return std::nullopt;
  }
  return joints;
}

}  // namespace cncd::daemon
