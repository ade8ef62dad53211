#include "cncd/interp/interpreter.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <variant>

#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

std::string InterpError::to_string() const {
  // The file loaders' messages name their file and line already ("FILE:LINE: ...").
  if (line == 0 && !file.empty() && message.rfind(file + ":", 0) == 0) return message;
  std::string text = file;
  if (line > 0) {
    text += ":" + std::to_string(line);
    if (column > 0) text += ":" + std::to_string(column);
  }
  text += ": " + message;
  return text;
}

Interpreter::Impl::Impl(InterpOptions opts)
    : options_(std::move(opts)), dialect_(options_.dialect) {
  block_.clear();  // no block has run yet: state() reports no group 0 code
  parameters_.set_predefined([this](std::string_view name) { return predefined_parameter(name); });
  // A file that is not there yet starts from the defaults, as LinuxCNC does; whoever owns it
  // (the daemon) writes it later. One that is there but unreadable is an error.
  auto missing = [](const std::filesystem::path& path) {
    std::error_code ec;
    return !std::filesystem::exists(path, ec) && !ec;
  };
  // Loads `path` when given: nothing when it is not there, else the problem that refused it.
  auto load = [&](const std::filesystem::path& path, const char* when_missing,
                  auto&& read) -> std::optional<std::string> {
    if (path.empty()) return std::nullopt;
    if (missing(path)) {
      load_warnings_.push_back(path.string() + when_missing);
      return std::nullopt;
    }
    auto problem = read(path);
    if (problem) config_error_ = InterpError{path.string(), 0, 0, *problem};
    return problem;
  };
  parameter_file_refused_ =
      load(options_.parameter_file, ": parameter file does not exist; default parameters are used",
           [&](const std::filesystem::path& path) { return parameters_.load(path); })
          .has_value();
  load(options_.tool_table, ": tool table does not exist; the table is empty",
       [&](const std::filesystem::path& path) { return tools_.load(path); });
  reset_modal_state();
}

void Interpreter::Impl::reset_modal_state() {
  modal_ = ModalState{};
  modal_.units = options_.machine_units;
  cycle_ = CycleState{};
  comp_ = CompState{};
  parameters_.hide_position(false);
  spline_ = SplineState{};
  nx_ = NumeryxState{};
  nx_loops_.clear();
  const int system = to_int(parameters_.get(5220));
  modal_.coord_system = system >= 1 && system <= 9 ? system : 1;
  parameters_.set(5220, modal_.coord_system);
  load_coord_system(modal_.coord_system);
  // The G92 offset comes back from the parameters only while it is enabled (#5210).
  g92_offset_ = parameters_.get(5210) != 0.0 ? read_offset_parameters(kG92Base) : Pose{};
  control_.clear();
  calls_.clear();
  g7x_.reset();
  saved_modal_top_ = SavedModalState{};
  subs_.clear();
  preamble_done_ = false;
  ended_ = false;
  loops_without_motion_ = 0;
  seen_percent_ = false;
  text_seen_ = false;
  input_pending_ = false;
  probe_pending_ = false;
}

void Interpreter::Impl::emit_command(const CanonCommand& command) {
  if (g7x_ && g7x_capture(command)) return;
  // A command held back behind a compensated move is checked at its own line too;
  // send_command() checks every other one as it goes out.
  if (!comp_.queue.empty() && !all_finite(command.op))
    fail("Result is not a finite number (overflow)");
  if (Comp::comp_hold_back(*this, command)) return;
  send_command(command);
}

void Interpreter::Impl::send_command(const CanonCommand& command) {
  // Held-back moves are checked here, as they leave (an offset can overflow too).
  if (!all_finite(command.op)) fail("Result is not a finite number (overflow)");
  const bool moves = std::holds_alternative<StraightTraverse>(command.op) ||
                     std::holds_alternative<StraightFeed>(command.op) ||
                     std::holds_alternative<ArcFeed>(command.op) ||
                     std::holds_alternative<NurbsFeed>(command.op) ||
                     std::holds_alternative<Dwell>(command.op) ||
                     std::holds_alternative<StraightProbe>(command.op) ||
                     std::holds_alternative<RigidTap>(command.op);
  if (moves) loops_without_motion_ = 0;  // a move or a dwell
  track_standalone(command.op);
  sink_->emit(command);
}

void Interpreter::Impl::emit_comment(const std::string& text) {
  emit(Comment{text});
}

void Interpreter::Impl::emit_preamble() {
  sync_standalone();
  emit(UseLengthUnits{modal_.units});
  emit_g5x();
  emit_g92();
  emit(SetXyRotation{rotation_deg_});
  emit(SetFeedReference{});
  emit(OnReset{});
  preamble_done_ = true;
}

InterpError Interpreter::Impl::make_error(const Failure& failure) const {
  InterpError error;
  error.file = sources_.empty() ? program_name_ : sources_.back().name();
  error.line = current_line_;
  if (failure.line > 0) {
    error.file = failure.file;
    error.line = failure.line;
  }
  error.column = failure.column;
  error.message = failure.message;
  return error;
}

Interpreter::Step Interpreter::Impl::step(CanonSink& sink) {
  if (error_) return Step::error;
  if (ended_) return Step::end;
  sink_ = &sink;
  try {
    if (sources_.empty()) fail("No program open");
    const bool first = !preamble_done_;
    if (first) {
      emit_preamble();
      run_startup_code();
    } else if (resend_g5x_) {
      // The active origin was changed between programs: the canon layer learns it first.
      emit_g5x();
      if (resend_g92_) emit_g92();
      emit(SetXyRotation{rotation_deg_});
    }
    // So is a tool length offset taken again for the tool in the spindle.
    if (resend_tool_offset_ && !first) emit(UseToolLengthOffset{tool_offset_});
    resend_g5x_ = false;
    resend_g92_ = false;
    resend_tool_offset_ = false;
    read_probe_result();  // LinuxCNC reads the probe's result before the input's
    read_input_result();
    LineSource& source = sources_.back();
    line_offset_ = source.tell();
    line_before_ = source.line_number();
    if (!source.read_line(line_)) {
      current_line_ = source.line_number();
      if (mdi_ && sources_.size() == 1) {
        ended_ = true;  // an MDI line needs no program end
        return Step::end;
      }
      fail(seen_percent_ ? "File ended with no percent sign"
                         : "File ended with no percent sign or program end");
    }
    current_line_ = source.line_number();
    if (delimiter_line()) return ended_ ? Step::end : Step::block;
    run_line();
    publish_parameters();
    if (ended_) check_percent_after_end();
    return ended_ ? Step::end : Step::block;
  } catch (const Failure& failure) {
    error_ = make_error(failure);
    close_probe_file();  // the run is over: what it probed is in the file
    return Step::error;
  }
}

// RS274NGC_STARTUP_CODE: blocks run before the program's first line, as LinuxCNC's task
// does when it starts the interpreter. Reported as line 0.
void Interpreter::Impl::run_startup_code() {
  std::size_t start = 0;
  const std::string& code = options_.startup_code;
  while (start < code.size()) {
    std::size_t end = code.find('\n', start);
    if (end == std::string::npos) end = code.size();
    line_.assign(code, start, end - start);
    start = end + 1;
    current_line_ = 0;
    parser_.parse(line_, block_);
    if (block_.o_kind != OKind::none) fail("O-words are not allowed in the startup code");
    run_line();
  }
}

void Interpreter::Impl::run_line() {
  parser_.set_dialect(dialect_);
  if (nx_loops_.empty()) {
    parser_.set_gil_loop(0, 0);
  } else {
    parser_.set_gil_loop(nx_loops_.back().var, nx_loops_.back().end);
  }
  parser_.parse(line_, block_);
  if (block_.block_delete && options_.block_delete) return;
  // The tool (#5400-#5413) and position (#5420-#5428) parameters and the predefined names
  // belong to the interpreter.
  // All of a line's assignments or none of them.
  for (const auto& assignment : block_.numbered_assignments) {
    if (assignment.number >= 5400 && assignment.number <= 5428) fail("Parameter is readonly");
    parameters_.check(assignment.number, assignment.value, assignment.column);
  }
  for (int i = 0; i < block_.named_assignment_count; ++i) {
    const std::string& name = block_.named_assignments[static_cast<std::size_t>(i)].first;
    if (predefined_parameter(name)) fail("Cannot assign to read-only parameter #<" + name + ">");
  }
  for (const auto& assignment : block_.numbered_assignments)
    parameters_.set(assignment.number, assignment.value, assignment.column);
  for (int i = 0; i < block_.named_assignment_count; ++i) {
    const auto& [name, value] = block_.named_assignments[static_cast<std::size_t>(i)];
    parameters_.set_named(name, value);
  }
  if (handle_fanuc_codes()) return;
  if (block_.o_kind != OKind::none) {
    handle_o_word();
    return;
  }
  if (block_.nx_loop != Block::Loop::none && handle_numeryx_loop()) return;
  execute_block();
}

Interpreter::Interpreter(InterpOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {}

Interpreter::~Interpreter() = default;

void Interpreter::set_position(const Pose& position) {
  impl_->pos_ = position;
  impl_->sync_standalone();
}

void Interpreter::set_tcp_switch(std::function<Pose(const Pose& machine, bool tcp_on)> tcp_switch) {
  impl_->options_.tcp_switch = std::move(tcp_switch);
}

void Interpreter::set_machine_position(const Pose& machine) {
  Pose program = machine;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (is_linear_axis(static_cast<int>(axis)))
      program[axis] = impl_->to_program_units(program[axis]);
  }
  impl_->pos_ = impl_->machine_to_program(program);
  impl_->sync_standalone();
}

// A program, from a file or a text, runs from its first line in the modal state it starts
// with, in the dialect it names.
std::optional<InterpError> Interpreter::Impl::start_program(LineSource source) {
  sources_.push_back(std::move(source));
  if (error_) return error_;
  reset_modal_state();
  try {
    detect_dialect();
  } catch (const Failure& failure) {
    error_ = make_error(failure);
    return error_;
  }
  return std::nullopt;
}

std::optional<InterpError> Interpreter::open(const std::filesystem::path& program,
                                             std::shared_ptr<const SubroutineIndex> index) {
  impl_->mdi_ = false;
  impl_->sources_.clear();
  impl_->sub_index_ = std::move(index);
  impl_->close_probe_file();
  std::error_code ec;
  const auto absolute = std::filesystem::absolute(program, ec);
  impl_->program_dir_ = ec ? program.parent_path() : absolute.parent_path();
  impl_->error_ = impl_->config_error_;  // a new program starts without the last one's error
  impl_->program_name_ = program.string();
  LineSource source;
  if (const std::string why = source.open_file(program); !why.empty()) {
    impl_->error_ = InterpError{program.string(), 0, 0, "Unable to open file: " + why};
    return impl_->error_;
  }
  return impl_->start_program(std::move(source));
}

std::optional<InterpError> Interpreter::open_mdi(std::string line) {
  impl_->sources_.clear();
  impl_->sub_index_.reset();
  impl_->program_dir_.clear();  // a probe file opened by an earlier MDI line stays open
  impl_->error_ = impl_->config_error_;
  impl_->program_name_ = "MDI";
  LineSource source;
  source.open_text(std::move(line), "MDI");
  impl_->sources_.push_back(std::move(source));
  if (impl_->error_) return impl_->error_;
  // Modal state carries over from the previous MDI line or program, as in LinuxCNC; MDI reads
  // the machine's dialect.
  impl_->dialect_ = impl_->options_.dialect;
  impl_->mdi_ = true;
  impl_->ended_ = false;
  impl_->text_seen_ = false;  // a '%' alone in MDI opens, and so does nothing, as before
  impl_->loops_without_motion_ = 0;
  impl_->control_.clear();
  impl_->calls_.clear();
  impl_->g7x_.reset();
  return std::nullopt;
}

std::optional<InterpError> Interpreter::open_string(std::string text, std::string name) {
  impl_->mdi_ = false;
  impl_->sources_.clear();
  impl_->sub_index_.reset();
  impl_->close_probe_file();
  impl_->program_dir_.clear();
  impl_->error_ = impl_->config_error_;
  impl_->program_name_ = name;
  LineSource source;
  source.open_text(std::move(text), std::move(name));
  return impl_->start_program(std::move(source));
}

Interpreter::Step Interpreter::step(CanonSink& sink) {
  return impl_->step(sink);
}

const std::optional<InterpError>& Interpreter::error() const {
  return impl_->error_;
}

const std::optional<InterpError>& Interpreter::load_error() const {
  return impl_->config_error_;
}

const std::vector<std::string>& Interpreter::load_warnings() const {
  return impl_->load_warnings_;
}

void Interpreter::set_input_result(double value) {
  impl_->input_pending_ = false;
  impl_->parameters_.set(5399, std::isfinite(value) ? value : -1.0);
}

void Interpreter::set_probe_result(const Pose& trip_machine, bool tripped) {
  Pose program = trip_machine;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    if (is_linear_axis(static_cast<int>(axis)))
      program[axis] = impl_->to_program_units(program[axis]);
  }
  program = impl_->machine_to_program(program);
  impl_->probe_pending_ = false;
  impl_->sync_standalone();
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    impl_->parameters_.set(5061 + static_cast<int>(axis), program[axis]);
  impl_->parameters_.set(5070, tripped ? 1.0 : 0.0);
  try {
    impl_->write_probe_line();
  } catch (const Failure& failure) {
    // The probe's line is the current one: the next step() reports it there.
    if (!impl_->error_) impl_->error_ = impl_->make_error(failure);
  }
}

int Interpreter::current_line() const {
  return impl_->current_line_;
}
int Interpreter::program_line() const {
  return impl_->sources_.size() > 1 ? impl_->sources_.front().line_number() : impl_->current_line_;
}

Dialect Interpreter::dialect() const {
  return impl_->dialect_;
}

void Interpreter::set_block_delete(bool on) {
  impl_->options_.block_delete = on;
}

std::optional<InterpError> Interpreter::save_parameters() const {
  const auto& path = impl_->options_.parameter_file;
  if (path.empty()) return std::nullopt;
  if (impl_->parameter_file_refused_) {
    return InterpError{path.string(), 0, 0,
                       path.string() + ": not written: it was refused when it was read"};
  }
  if (auto problem = impl_->parameters_.save(path)) {
    return InterpError{path.string(), 0, 0, *problem};
  }
  return std::nullopt;
}

std::optional<InterpError> run_program(Interpreter& interp, CanonSink& sink) {
  for (;;) {
    switch (interp.step(sink)) {
      case Interpreter::Step::block:
        continue;
      case Interpreter::Step::end:
        return std::nullopt;
      case Interpreter::Step::error:
        return interp.error();
    }
  }
}

}  // namespace cncd::interp
