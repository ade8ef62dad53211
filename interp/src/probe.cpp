// G38.2-G38.5 straight probes with LinuxCNC's checks, the result the machine hands back (or,
// without a machine, the one LinuxCNC's standalone interpreter makes up), and the probe file
// of (PROBEOPEN name) / (PROBECLOSE).
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
  } else if (const auto* nurbs = std::get_if<NurbsFeed>(&op)) {
    if (!nurbs->points.empty()) s.pos = nurbs->points.back();
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

// LinuxCNC's canon acts on these two comments (exactly so, in capitals). The name is a file
// name in the probe directory (InterpOptions::probe_dir; without one, the program's directory).
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
  if (const auto problem = probe_name_problem(name); !problem.empty()) fail(problem);
  ProbeFileTarget target;
  target.name = name;
  if (!options_.probe_dir.empty()) {
    target.dir = options_.probe_dir;
  } else if (!program_dir_.empty()) {
    target.dir = program_dir_;
  } else if (!options_.subroutine_path.empty() && !options_.subroutine_path.front().empty()) {
    target.dir = options_.subroutine_path.front();
  } else {
    fail("Cannot open probe file " + name +
         ": MDI has no program directory to put it in (set [RS274NGC] SUBROUTINE_PATH)");
  }
  std::error_code ec;
  if (const auto absolute = std::filesystem::absolute(target.dir, ec); !ec)
    target.dir = absolute.lexically_normal();
  target.state_files = options_.state_files;
  target.state_files.push_back(options_.parameter_file);
  target.state_files.push_back(options_.tool_table);
  if (const auto problem = probe_target_problem(target); !problem.empty()) fail(problem);
  close_probe_file();
  probe_target_ = std::move(target);
  return true;
}

void Interpreter::Impl::close_probe_file() {
  if (probe_opened_) probe_writer().close();
  probe_opened_ = false;
  probe_target_.reset();
}

ProbeFileWriter& Interpreter::Impl::probe_writer() {
  if (!probe_writer_) {
    probe_writer_ =
        options_.probe_writer ? options_.probe_writer : std::make_shared<SyncProbeWriter>();
  }
  return *probe_writer_;
}

// "%f %f %f %f %f %f %f %f %f": X Y Z A B C U V W of #5061-#5069, as LinuxCNC writes them.
// The first result empties the file, as LinuxCNC's opening it does; each is written at once.
void Interpreter::Impl::write_probe_line() {
  if (!probe_target_) return;
  const std::string where = (sources_.empty() ? program_name_ : sources_.back().name()) + ":" +
                            std::to_string(current_line_);
  if (!probe_opened_) {
    const std::string problem = probe_writer().open(*probe_target_, where);
    if (!problem.empty()) {
      probe_target_.reset();
      fail(problem);
    }
    probe_opened_ = true;
  }
  std::string line;
  char number[400];
  for (int axis = 0; axis < kAxes; ++axis) {
    const int n = std::snprintf(number, sizeof number, "%f", parameters_.get(5061 + axis));
    if (n > 0) line.append(number, static_cast<std::size_t>(n));
    line += axis + 1 < kAxes ? ' ' : '\n';
  }
  if (const std::string problem = probe_writer().write(line, where); !problem.empty()) {
    close_probe_file();
    fail(problem);
  }
}

}  // namespace cncd::interp
