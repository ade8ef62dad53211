// The '%' lines that may open and close a program, as rs274 reads them: the opening one after
// nothing but blank lines, the closing one ending the program wherever it is read, even while
// an if is skipped or a sub is sought; what follows it is no part of the program.
#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

bool Interpreter::Impl::delimiter_line() {
  const bool main_file = calls_.empty() && sources_.size() == 1;
  if (is_percent_line(line_)) {
    if (!text_seen_ && main_file) {
      seen_percent_ = true;
      text_seen_ = true;
      return true;
    }
    if (seen_percent_) {
      // cncd's own: rs274 ends here with its last compensated move still held back, never
      // sent; the move the program asked for is cut.
      Comp::comp_flush(*this);
      emit(Finish{});
      close_probe_file();
      ended_ = true;
      return true;
    }
  }
  text_seen_ = text_seen_ || line_.find_first_not_of(" \t\r") != std::string::npos;
  return false;
}

bool Interpreter::Impl::at_closing_percent() const {
  return seen_percent_ && sources_.size() == 1 && is_percent_line(line_);
}

void Interpreter::Impl::end_at_closing_percent(const std::string& name, bool sub, int line) {
  current_line_ = line;
  emit(Finish{});
  throw Failure{"Failed to find sub '" + std::string(sub ? "O" : "O#") + name + "' before EOF", 0,
                source().name(), line};
}

// rs274 reads on after M2 in a program opened with '%' and says so when no '%' closes it.
void Interpreter::Impl::check_percent_after_end() {
  if (!seen_percent_ || sources_.empty()) return;
  bool closed = false;
  if (sub_index_ && sources_.size() == 1) {
    closed = sub_index_->closing_percent.offset >= source().tell();
  } else {
    while (!closed && source().read_line(line_))
      closed = is_percent_line(line_);
  }
  if (!closed) emit_comment("interpreter: percent sign missing from end of file");
}

}  // namespace cncd::interp
