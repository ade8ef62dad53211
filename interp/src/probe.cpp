// G38.2-G38.5 straight probes with LinuxCNC's checks, the result the machine hands back (or,
// without a machine, the one LinuxCNC's standalone interpreter makes up), and the probe file
// of (PROBEOPEN name) / (PROBECLOSE).
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

// Why `path` could not be opened for writing, without creating or emptying it; empty if it
// could. A check (cncd-check, the daemon's program.open) runs the program too, and must leave
// the results of the last run alone.
std::string open_problem(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(status)) return std::strerror(EISDIR);
  if (std::filesystem::exists(status)) {
    return ::access(path.c_str(), W_OK) == 0 ? std::string() : std::strerror(errno);
  }
  const auto dir = path.parent_path();
  if (!std::filesystem::is_directory(dir, ec)) return std::strerror(ENOENT);
  return ::access(dir.c_str(), W_OK | X_OK) == 0 ? std::string() : std::strerror(errno);
}

}  // namespace

void Interpreter::Impl::do_probe(int code) {
  // cncd's own check first (LinuxCNC would probe at the last per-minute feed and ignore the
  // inverse time), then LinuxCNC's in its order (cutter compensation, its first, is never on).
  if (modal_.feed_mode == FeedMode::inverse_time) fail("Cannot probe in inverse time feed mode");
  if (modal_.feed_rate == 0.0) fail("Cannot probe with zero feed rate");
  if (modal_.feed_mode == FeedMode::units_per_rev) fail("Cannot probe with feed per rev mode");
  const Pose end = target_from_words();
  // G38.3 and G38.5 may start where they end (no move, no error); G38.2 and G38.4 may not.
  if ((code == 382 || code == 384) && end == pos_) fail("Start point too close to probe point");
  emit(TurnProbeOn{});
  emit(StraightProbe{end, static_cast<ProbeKind>(code - 382)});
  emit(TurnProbeOff{});
  probe_pending_ = true;
  probe_end_ = end;
  // Until the machine says where it stopped (set_machine_position), the move reached its end.
  pos_ = end;
}

// The next line sees the probe's result. Without one from the machine (set_probe_result),
// LinuxCNC's standalone interpreter takes the programmed end as where the probe tripped, 0 for
// #5070, and its canon's position, backed off from the end (track_standalone()).
void Interpreter::Impl::read_probe_result() {
  if (!probe_pending_) return;
  probe_pending_ = false;
  for (int axis = 0; axis < kAxes; ++axis)
    parameters_.set(5061 + axis, probe_end_[static_cast<std::size_t>(axis)]);
  parameters_.set(5070, 0.0);
  for (std::size_t axis = 0; axis < 6; ++axis)
    pos_[axis] = standalone_.pos[axis];
  for (std::size_t axis = 6; axis < kAxes; ++axis)
    pos_[axis] = probe_end_[axis];  // rs274 has no U V W
}

void Interpreter::Impl::sync_standalone() {
  standalone_.pos = pos_;
  standalone_.g5x = g5x_offset_;
  standalone_.g92 = g92_offset_;
  standalone_.units = modal_.units;
}

// As rs274's canon: a move ends where it says; a probe leaves the tool 0.254 mm (0.01 in)
// back from its end toward where it started, or where it started when that is its end; a new
// offset shifts the position by the change (X Y Z A B C); new units scale X Y Z.
void Interpreter::Impl::track_standalone(const CanonOp& op) {
  StandaloneCanon& s = standalone_;
  if (const auto* feed = std::get_if<StraightFeed>(&op)) {
    s.pos = feed->end;
  } else if (const auto* traverse = std::get_if<StraightTraverse>(&op)) {
    s.pos = traverse->end;
  } else if (const auto* arc = std::get_if<ArcFeed>(&op)) {
    s.pos = arc->end();
  } else if (const auto* probe = std::get_if<StraightProbe>(&op)) {
    double d[3];
    double distance = 0;
    for (std::size_t axis = 0; axis < 3; ++axis) {
      d[axis] = s.pos[axis] - probe->end[axis];
      distance += d[axis] * d[axis];
    }
    distance = std::sqrt(distance);
    if (distance != 0.0) {
      const double backoff = s.units == Units::inches ? 0.01 : 0.254;
      for (std::size_t axis = 0; axis < 3; ++axis)
        s.pos[axis] = probe->end[axis] + backoff * (d[axis] / distance);
    }
    for (std::size_t axis = 3; axis < kAxes; ++axis)
      s.pos[axis] = probe->end[axis];
  } else if (const auto* g5x = std::get_if<SetG5xOffset>(&op)) {
    for (std::size_t axis = 0; axis < 6; ++axis)
      s.pos[axis] += s.g5x[axis] - g5x->offset[axis];
    s.g5x = g5x->offset;
  } else if (const auto* g92 = std::get_if<SetG92Offset>(&op)) {
    for (std::size_t axis = 0; axis < 6; ++axis)
      s.pos[axis] += s.g92[axis] - g92->offset[axis];
    s.g92 = g92->offset;
  } else if (const auto* units = std::get_if<UseLengthUnits>(&op)) {
    if (units->units != s.units) {
      const double factor = unit_factor(s.units, units->units);
      for (std::size_t axis = 0; axis < 3; ++axis) {
        s.pos[axis] *= factor;
        s.g5x[axis] *= factor;
        s.g92[axis] *= factor;
      }
      s.units = units->units;
    }
  }
}

// LinuxCNC's canon acts on these two comments (exactly so, in capitals); a relative name is
// taken from the program's directory (cncd's choice: LinuxCNC's is its own working directory).
bool Interpreter::Impl::probe_file_comment(const std::string& text) {
  if (text.starts_with("PROBECLOSE")) {
    close_probe_file();
    return true;
  }
  if (!text.starts_with("PROBEOPEN")) return false;
  std::string name = text.substr(9);
  const std::size_t first = name.find_first_not_of(" \t");
  const std::size_t last = name.find_last_not_of(" \t");
  name = first == std::string::npos ? std::string() : name.substr(first, last - first + 1);
  if (name.empty()) fail("PROBEOPEN without a file name: (PROBEOPEN results.txt)");
  std::filesystem::path path = name;
  if (path.is_relative()) {
    if (!program_dir_.empty()) {
      path = program_dir_ / path;
    } else if (!options_.subroutine_path.empty() && !options_.subroutine_path.front().empty()) {
      path = options_.subroutine_path.front() / path;
    } else {
      fail("Cannot open probe file " + name +
           ": a relative name is taken from the program's directory, and MDI has none (give a "
           "full path, or set [RS274NGC] SUBROUTINE_PATH)");
    }
  }
  std::error_code ec;
  const auto absolute = std::filesystem::absolute(path, ec);
  if (!ec) path = absolute.lexically_normal();
  const std::string problem = open_problem(path);
  if (!problem.empty()) fail("Cannot open probe file " + path.string() + ": " + problem);
  close_probe_file();
  probe_path_ = path;
  return true;
}

void Interpreter::Impl::close_probe_file() {
  probe_file_.reset();
  probe_path_.clear();
}

// "%f %f %f %f %f %f %f %f %f": X Y Z A B C U V W of #5061-#5069, as LinuxCNC writes them.
// The first result empties the file, as LinuxCNC's opening it does; each is flushed.
void Interpreter::Impl::write_probe_line() {
  if (probe_path_.empty()) return;
  if (!probe_file_) {
    probe_file_.reset(std::fopen(probe_path_.c_str(), "w"));
    if (!probe_file_) {
      const std::string why = std::strerror(errno);
      const std::string name = probe_path_.string();
      close_probe_file();
      fail("Cannot open probe file " + name + ": " + why);
    }
  }
  std::string line;
  char number[400];
  for (int axis = 0; axis < kAxes; ++axis) {
    const int n = std::snprintf(number, sizeof number, "%f", parameters_.get(5061 + axis));
    if (n > 0) line.append(number, static_cast<std::size_t>(n));
    line += axis + 1 < kAxes ? ' ' : '\n';
  }
  const bool written = std::fwrite(line.data(), 1, line.size(), probe_file_.get()) == line.size() &&
                       std::fflush(probe_file_.get()) == 0;
  if (!written) {
    const std::string why = std::strerror(errno);
    const std::string name = probe_path_.string();
    close_probe_file();
    fail("Cannot write probe file " + name + ": " + why);
  }
}

}  // namespace cncd::interp
