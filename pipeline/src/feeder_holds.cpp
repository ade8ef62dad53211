// The feeder's holds (a tool change, a user M code) and what a run from a line puts in front of
// its first move: the tool, spindle and coolant the skipped lines left in force.
#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cncd/pipeline/feeder.hpp"
#include "number_text.hpp"

namespace cncd::pipeline {

void ProgramFeeder::add_hold(HoldInfo info, int line) {
  motion::IoAction a;
  a.kind = motion::IoAction::Kind::hold;
  a.hold = info.kind;
  a.hold_id = next_hold_id_++;
  info.line = line;
  holds_[a.hold_id] = std::move(info);
  add_action(a, line);
}

const HoldInfo* ProgramFeeder::hold(std::uint32_t id) const {
  const auto found = holds_.find(id);
  return found != holds_.end() ? &found->second : nullptr;
}

void ProgramFeeder::erase_tool_changes() {
  std::erase_if(holds_,
                [](const auto& h) { return h.second.kind == motion::IoAction::Hold::tool_change; });
}

bool ProgramFeeder::drop_pending(motion::AxisPose& end) {
  bool moved = false;
  for (const auto& move : pending_) {
    if (move.kind == motion::Move::Kind::dwell || move.kind == motion::Move::Kind::action) continue;
    end = move.end;
    moved = true;
  }
  pending_.clear();
  return moved;
}

bool ProgramFeeder::drop_pending_before(int line, motion::AxisPose& end) {
  bool moved = false;
  while (!pending_.empty() && pending_.front().line < line) {
    const motion::Move& move = pending_.front();
    if (move.kind != motion::Move::Kind::dwell && move.kind != motion::Move::Kind::action) {
      end = move.end;
      moved = true;
    }
    pending_.pop_front();
  }
  return moved;
}

bool ProgramFeeder::moves_from(int line) const {
  return std::any_of(pending_.begin(), pending_.end(), [line](const motion::Move& move) {
    return move.line >= line && move.kind != motion::Move::Kind::dwell &&
           move.kind != motion::Move::Kind::action;
  });
}

void ProgramFeeder::queue_tool_change(int number, int line, int before) {
  tool_ = number;
  const config::ToolChangeConfig* change = machine_ ? &machine_->tool_change : nullptr;
  if (change != nullptr && change->has_position) {
    // LinuxCNC's TOOL_CHANGE_POSITION: one traverse there, machine coordinates; the axes it
    // does not name stay where they are.
    motion::Move there;
    there.kind = motion::Move::Kind::traverse;
    there.line = line;
    there.path_mode = motion::Move::PathMode::exact_stop;
    there.end = end_;
    for (int i = 0; i < motion::kAxes; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (change->position_given[k]) there.end[k] = change->position[k];
    }
    pending_.push_back(there);
    end_ = there.end;
  }
  HoldInfo info;
  info.kind = motion::IoAction::Hold::tool_change;
  info.tool = number;
  info.tool_before = before;
  add_hold(std::move(info), line);
}

void ProgramFeeder::change_tool_first(int number, int line, const motion::AxisPose& at,
                                      int in_spindle) {
  std::deque<motion::Move> rest;
  rest.swap(pending_);
  const motion::AxisPose end = end_;
  end_ = at;
  if (machine_ == nullptr || !machine_->tool_change.with_spindle_on) {
    motion::IoAction stop;
    stop.kind = motion::IoAction::Kind::spindle;
    add_action(stop, line);
  }
  queue_tool_change(number, line, in_spindle);
  end_ = end;
  pending_.insert(pending_.end(), rest.begin(), rest.end());
}

std::optional<std::string> ProgramFeeder::approach_first(const motion::AxisPose& from,
                                                         const motion::AxisPose& to, double safe_z,
                                                         int line, std::optional<double> feed) {
  approach_moves_ = 0;
  if (from == to) return std::nullopt;  // already there
  constexpr std::size_t kZ = 2;
  const bool has_z = machine_ == nullptr || machine_->axes[kZ].present;
  const double high = has_z ? std::max(from[kZ], safe_z) : from[kZ];
  std::vector<motion::Move> way;
  const auto add = [&](motion::Move::Kind kind, motion::AxisPose end) {
    motion::Move move;
    move.kind = kind;
    move.end = end;
    move.line = line;
    move.path_mode = motion::Move::PathMode::exact_stop;  // no corner of the way is cut
    way.push_back(move);
  };
  motion::AxisPose up = from;
  up[kZ] = high;
  if (up != from) add(motion::Move::Kind::traverse, up);
  motion::AxisPose over = to;
  over[kZ] = high;
  if (over != up) add(motion::Move::Kind::traverse, over);
  if (to != over) {
    const double down = feed.value_or(feed_per_second());
    if (!(down > 0)) {
      return "no feed is in force to move Z down to the line's start: set F on a line before "
             "it";
    }
    add(motion::Move::Kind::feed, to);
    way.back().feed = down;
  }
  pending_.insert(pending_.begin(), way.begin(), way.end());
  approach_moves_ = static_cast<int>(way.size());
  return std::nullopt;
}

void ProgramFeeder::restore_io_state() {
  std::deque<motion::Move> front;
  const auto push = [&](const motion::IoAction& a) {
    motion::Move move;
    move.kind = motion::Move::Kind::action;
    move.action = a;
    front.push_back(move);
  };
  push(spindle_action());
  motion::IoAction coolant;
  coolant.kind = motion::IoAction::Kind::coolant;
  coolant.flood = flood_;
  coolant.mist = mist_;
  push(coolant);
  if (spindle_direction_ != 0) {
    motion::IoAction at_speed;
    at_speed.kind = motion::IoAction::Kind::wait_at_speed;
    push(at_speed);
  }
  need_at_speed_ = false;
  pending_.insert(pending_.begin(), front.begin(), front.end());
}

}  // namespace cncd::pipeline
