// O-word control flow: subroutines (in the program file or in NAME.ngc on the subroutine
// path), if/elseif/else, while, do/while, repeat, break, continue, return. The program is
// re-read from remembered file offsets, so loops and calls cost no memory per line.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

std::string o_label(const std::string& name) {
  return std::isdigit(static_cast<unsigned char>(name.empty() ? 'x' : name[0])) ? "o" + name
                                                                                : "o<" + name + ">";
}

// Reads on until a line with this O-word name and one of `stops`; that line is then in
// `line_` and is the current line.
OKind Interpreter::Impl::skip_block(const std::string& name, std::initializer_list<OKind> stops) {
  const int start_line = current_line_;
  for (;;) {
    line_offset_ = source().tell();
    line_before_ = source().line_number();
    if (!source().read_line(line_)) {
      fail("EOF in file:" + source().name() + " seeking o-word: o<" + name +
           "> from line: " + std::to_string(start_line));
    }
    current_line_ = source().line_number();
    if (at_closing_percent())
      end_at_closing_percent(name, *stops.begin() == OKind::endsub, current_line_);
    OKind kind = OKind::none;
    if (!scan_o_line(line_, o_scan_name_, kind) || o_scan_name_ != name) continue;
    for (const OKind stop : stops) {
      if (kind == stop) return kind;
    }
  }
}

bool Interpreter::Impl::find_sub(const std::string& name) {
  // Search the rest of the program file first, as LinuxCNC does, then NAME.ngc files.
  const std::int64_t offset = source().tell();
  const int line_number = source().line_number();
  int closing_line = 0;  // the program's closing '%', where the search of its file ended
  OKind kind = OKind::none;
  if (sub_index_ && sources_.size() == 1) {
    if (find_indexed_sub(name, offset, closing_line)) return true;
  } else {
    while (source().read_line(line_)) {
      if (at_closing_percent()) {
        closing_line = source().line_number();
        break;
      }
      if (!scan_o_line(line_, o_scan_name_, kind) || o_scan_name_ != name) continue;
      if (kind == OKind::none) fail("Fanuc 'O....' subroutine must be called with 'M98'");
      if (kind == OKind::sub) {
        subs_[name] = SubInfo{sources_.size() - 1, source().tell(), source().line_number(), true};
        source().seek(offset, line_number);
        return true;
      }
    }
  }
  source().seek(offset, line_number);
  std::vector<std::filesystem::path> dirs = options_.subroutine_path;
  dirs.push_back(std::filesystem::path(program_name_).parent_path());
  for (const auto& dir : dirs) {
    const auto file = dir / (name + ".ngc");
    std::error_code error;  // a name too long for a file name is simply not found
    if (!std::filesystem::exists(file, error)) continue;
    LineSource sub_file;
    if (const std::string why = sub_file.open_file(file); !why.empty())
      fail("Cannot read subroutine file " + file.string() + ": " + why);
    while (sub_file.read_line(line_)) {
      if (scan_o_word(line_, o_scan_name_, kind) == OScan::o_word && kind == OKind::sub &&
          o_scan_name_ == name) {
        sources_.push_back(std::move(sub_file));
        subs_[name] = SubInfo{sources_.size() - 1, source().tell(), source().line_number(), true};
        return true;
      }
    }
  }
  if (closing_line > 0) end_at_closing_percent(name, true, closing_line);
  return false;
}

void Interpreter::Impl::do_call() {
  const std::string name = block_.o_name;
  const std::size_t caller = sources_.size() - 1;
  const std::int64_t return_offset = source().tell();
  const int return_line = source().line_number();
  if (calls_.size() >= 64) fail("Too many nested subroutine calls");
  // The call takes its arguments before it looks for the sub, as rs274 does: a name computed
  // on the way (o#1 sub) reads the arguments and the call's own local parameters.
  CallFrame frame;
  frame.name = name;
  frame.source = caller;
  frame.return_offset = return_offset;
  frame.return_line = return_line;
  frame.control_depth = control_.size();
  frame.nx_loop_depth = nx_loops_.size();
  for (int i = 0; i < 30; ++i) {
    frame.saved_parameters[static_cast<std::size_t>(i)] = parameters_.get(i + 1);
    const auto arg = static_cast<std::size_t>(i);
    parameters_.set(i + 1, arg < block_.call_args.size() ? block_.call_args[arg] : 0.0);
  }
  calls_.push_back(frame);
  parameters_.push_scope();
  const SubInfo& sub = known_sub(name, false);
  if (sub.fanuc) fail("Fanuc 'O....' subroutine must be called with 'M98'");
  if (sub.source != sources_.size() - 1) {
    // The sub lives in an already open file further down the stack: bring it back on top.
    fail("Subroutine " + o_label(name) + " is not reachable from here");
  }
  source().seek(sub.offset, sub.line_before);
}

const SubInfo& Interpreter::Impl::known_sub(const std::string& name, bool fanuc) {
  auto it = subs_.find(name);
  if (it != subs_.end()) return it->second;
  if (!(fanuc ? find_fanuc_sub(name) : find_sub(name))) {
    fail("EOF in file:" + source().name() + " seeking o-word: o<" + name +
         "> from line: " + std::to_string(current_line_));
  }
  return subs_.at(name);
}

void Interpreter::Impl::do_return(bool has_value, double value) {
  if (calls_.empty()) fail(label_error("not in a subroutine definition"));
  const CallFrame frame = calls_.back();
  if (nx_loops_.size() > frame.nx_loop_depth) {
    const ForFrame& open = nx_loops_.back();
    fail("for #" + std::to_string(open.var) + " of line " + std::to_string(open.for_line) +
         " has no next before the end of subroutine " + o_label(frame.name));
  }
  auto_restore_modal_state();
  calls_.pop_back();
  control_.resize(frame.control_depth);
  parameters_.pop_scope();
  for (int i = 0; i < 30 && !frame.fanuc; ++i)
    parameters_.set(i + 1, frame.saved_parameters[static_cast<std::size_t>(i)]);
  last_value_ = has_value ? value : 0.0;
  value_returned_ = has_value;
  while (sources_.size() - 1 > frame.source) {
    // Leaving a NAME.ngc file: keep it open only while a sub in it may be called again.
    for (auto it = subs_.begin(); it != subs_.end();) {
      it = it->second.source == sources_.size() - 1 ? subs_.erase(it) : std::next(it);
    }
    sources_.pop_back();
  }
  source().seek(frame.return_offset, frame.return_line);
  if (frame.g7x) finish_g7x();
}

// LinuxCNC's wording for O-word label errors: "LINE: what: 'the line as written'".
std::string Interpreter::Impl::label_error(const char* what) const {
  return std::to_string(current_line_) + ": " + what + ": '" + line_ + "'";
}

void Interpreter::Impl::skip_loop_end(const ControlFrame& frame) {
  if (frame.kind == OKind::do_) {
    skip_block(frame.name, {OKind::while_});
  } else if (frame.kind == OKind::repeat) {
    skip_block(frame.name, {OKind::endrepeat});
  } else {
    skip_block(frame.name, {OKind::endwhile});
  }
}

void Interpreter::Impl::handle_o_word() {
  const std::string& name = block_.o_name;
  const bool top_is_this = !control_.empty() && control_.back().name == name;
  switch (block_.o_kind) {
    case OKind::sub: {
      auto it = subs_.find(name);
      if (it != subs_.end() && it->second.found_by_search) {
        fail("File:" + source().name() + " line:" + std::to_string(current_line_) + " sub: o|" +
             name + "| found in illegal location");
      }
      subs_[name] = SubInfo{sources_.size() - 1, source().tell(), source().line_number(), false};
      skip_block(name, {OKind::endsub});
      return;
    }
    case OKind::endsub:
    case OKind::return_:
      if (!calls_.empty() && calls_.back().fanuc)
        fail("Fanuc 'O....' subroutine definition must end with 'M99'");
      do_return(block_.has_o_value, block_.o_value);
      return;
    case OKind::call:
      do_call();
      return;
    case OKind::if_:
      if (block_.o_value != 0.0) {
        control_.push_back(ControlFrame{OKind::if_, name, 0, 0, 0});
        return;
      }
      // Look for a branch that runs: an elseif whose condition holds, an else, or the end.
      for (;;) {
        // Only an elseif is read whole (for its condition): rs274 takes "o1 endiffy" for the
        // endif it seeks.
        const OKind found = skip_block(name, {OKind::elseif, OKind::else_, OKind::endif});
        if (found == OKind::endif) return;
        if (found == OKind::elseif) parser_.parse(line_, block_);
        if (found == OKind::else_ || block_.o_value != 0.0) {
          control_.push_back(ControlFrame{OKind::if_, name, 0, 0, 0});
          return;
        }
      }
    case OKind::elseif:
    case OKind::else_:
      // The branch before ran: skip the rest of the if.
      if (!top_is_this) fail(label_error("undefined O-word label"));
      control_.pop_back();
      skip_block(name, {OKind::endif});
      return;
    case OKind::endif:
      if (!top_is_this) fail(label_error("undefined O-word label"));
      control_.pop_back();
      return;
    case OKind::do_:
      control_.push_back(
          ControlFrame{OKind::do_, name, source().tell(), source().line_number(), 0});
      return;
    case OKind::while_:
      if (top_is_this && control_.back().kind == OKind::do_) {
        // The end of a do loop.
        if (block_.o_value != 0.0) {
          loop_back(control_.back().offset, control_.back().line_before);
        } else {
          control_.pop_back();
        }
        return;
      }
      if (block_.o_value == 0.0) {
        if (top_is_this) control_.pop_back();
        skip_block(name, {OKind::endwhile});
        return;
      }
      if (!top_is_this) {
        control_.push_back(ControlFrame{OKind::while_, name, line_offset_, line_before_, 0});
      }
      return;
    case OKind::endwhile:
      if (!top_is_this || control_.back().kind != OKind::while_) {
        fail(label_error("undefined O-word label"));
      }
      loop_back(control_.back().offset, control_.back().line_before);
      return;
    case OKind::repeat: {
      const int count = to_int(std::nearbyint(block_.o_value));
      if (count <= 0) {
        skip_block(name, {OKind::endrepeat});
        return;
      }
      control_.push_back(
          ControlFrame{OKind::repeat, name, source().tell(), source().line_number(), count});
      return;
    }
    case OKind::endrepeat:
      if (!top_is_this || control_.back().kind != OKind::repeat) {
        fail(label_error("undefined O-word label"));
      }
      if (--control_.back().remaining > 0) {
        loop_back(control_.back().offset, control_.back().line_before);
      } else {
        control_.pop_back();
      }
      return;
    case OKind::break_:
    case OKind::continue_: {
      // Leave the if blocks nested in the loop, then end or restart the loop.
      while (!control_.empty() && control_.back().name != name)
        control_.pop_back();
      if (control_.empty()) fail(label_error("undefined O-word label"));
      ControlFrame& loop = control_.back();
      if (block_.o_kind == OKind::break_) {
        const ControlFrame ended = loop;
        control_.pop_back();
        skip_loop_end(ended);
      } else if (loop.kind == OKind::repeat) {
        if (--loop.remaining > 0) {
          loop_back(loop.offset, loop.line_before);
        } else {
          const ControlFrame ended = loop;
          control_.pop_back();
          skip_loop_end(ended);
        }
      } else if (loop.kind == OKind::do_) {
        skip_block(name, {OKind::while_});
        parser_.parse(line_, block_);
        handle_o_word();
      } else {
        loop_back(loop.offset, loop.line_before);
      }
      return;
    }
    case OKind::none:
      return;
  }
}

void Interpreter::Impl::loop_back(std::int64_t offset, int line_before) {
  if (++loops_without_motion_ > options_.max_loops_without_motion) {
    fail("Endless loop: " + std::to_string(options_.max_loops_without_motion) +
         " loop iterations without a move or dwell");
  }
  source().seek(offset, line_before);
}

}  // namespace cncd::interp
