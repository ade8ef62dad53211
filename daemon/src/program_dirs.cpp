#include "program_dirs.hpp"

#include <fstream>

namespace cncd::daemon {
namespace {

namespace fs = std::filesystem;

// `path` and `dir` are canonical: `path` is `dir` or lies below it.
bool within(const fs::path& path, const fs::path& dir) {
  auto p = path.begin();
  for (auto d = dir.begin(); d != dir.end(); ++d, ++p) {
    if (p == path.end() || *p != *d) return false;
  }
  return true;
}

bool in_any(const fs::path& path, const std::vector<fs::path>& dirs) {
  for (const auto& dir : dirs) {
    std::error_code ec;
    const fs::path real = fs::canonical(dir, ec);
    if (!ec && within(path, real)) return true;
  }
  return false;
}

std::string list(const std::vector<fs::path>& dirs) {
  std::string out;
  for (const auto& dir : dirs)
    out += (out.empty() ? "" : ", ") + dir.string();
  return out.empty() ? "none configured" : out;
}

}  // namespace

ProgramFile find_program(const std::string& requested, const std::vector<fs::path>& dirs) {
  const std::string cannot = "cannot open program '" + requested + "': ";
  // The same words for every path outside, whether it exists, is a symlink leading out or
  // cannot even be looked at.
  const ProgramFile outside{
      "", cannot + "programs open only from the program directories (" + list(dirs) + ")"};
  if (requested.find('\0') != std::string::npos) return outside;
  fs::path path(requested);
  if (path.is_relative()) {
    if (dirs.empty()) return outside;
    path = dirs.front() / path;
  }
  std::error_code ec;
  const fs::path real = fs::canonical(path, ec);
  if (ec) {
    // Not there (or not reachable): said so only when the path leads into a directory, the
    // existing part of it with its symlinks resolved.
    std::error_code ec2;
    const fs::path near = fs::weakly_canonical(path, ec2);
    if (ec2 || !in_any(near, dirs)) return outside;
    return {"", cannot + ec.message()};
  }
  if (!in_any(real, dirs)) return outside;
  if (!fs::is_regular_file(real, ec)) return {"", cannot + "not a regular file"};
  if (!std::ifstream(real)) return {"", cannot + "not readable"};
  return {real.string(), ""};
}

}  // namespace cncd::daemon
