// The operator's setup between programs: the tool table (tool.list / tool.set) and the
// coordinate system origins (offsets.get / offsets.set).
#include <algorithm>

#include "cncd/interp/stored_values.hpp"
#include "persist.hpp"
#include "task.hpp"
#include "tool_file.hpp"

namespace cncd::daemon {

std::vector<interp::ToolEntry> Task::tools() const {
  return interp_->tools();
}

std::optional<interp::ToolEntry> Task::find_tool(int number) const {
  return interp_->tool(number);
}

void Task::set_tool(const interp::ToolEntry& entry) {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI command is running");
  if (config_.tool_table.empty()) {
    throw TaskError(TaskErrorKind::wrong_state,
                    "the machine has no tool table ([EMCIO] TOOL_TABLE)");
  }
  // Before the file: a value the interpreter would refuse never reaches the disk.
  if (auto problem = interp::tool_entry_problem(entry))
    throw TaskError(TaskErrorKind::bad_value, *problem);
  auto tools = interp_->tools();
  const auto it = std::find_if(tools.begin(), tools.end(),
                               [&](const auto& t) { return t.number == entry.number; });
  if (it != tools.end()) {
    *it = entry;
  } else {
    tools.push_back(entry);
    std::sort(tools.begin(), tools.end(),
              [](const auto& a, const auto& b) { return a.number < b.number; });
  }
  // The file first: when it cannot be written, nothing has changed.
  const std::string error = atomic_write_file(config_.tool_table, format_tool_table(tools));
  if (!error.empty()) throw TaskError(TaskErrorKind::save_failed, error);
  if (auto problem = interp_->set_tool(entry)) throw TaskError(TaskErrorKind::bad_value, *problem);
  saved_tools_ = std::move(tools);
  events_.add("info", "tools", "tool " + std::to_string(entry.number) + " changed");
}

std::string Task::save_setup_files() {
  std::string problems;
  auto parameters = interp_->persistent_parameters();
  if (parameters != saved_parameters_) {
    if (const auto error = interp_->save_parameters()) {
      interp_->restore_persistent_parameters(saved_parameters_);
      problems = error->to_string();
      events_.add("error", "parameters", problems);
    } else {
      saved_parameters_ = std::move(parameters);
    }
  }
  auto tools = interp_->tools();
  if (!config_.tool_table.empty() && tools != saved_tools_) {
    if (const std::string error = atomic_write_file(config_.tool_table, format_tool_table(tools));
        !error.empty()) {
      interp_->set_tools(saved_tools_);
      problems += (problems.empty() ? "" : "; ") + error;
      events_.add("error", "tools", error);
    } else {
      saved_tools_ = std::move(tools);
    }
  }
  return problems;
}

OffsetsReport Task::offsets() const {
  const interp::InterpState st = interp_->state();
  OffsetsReport out;
  out.active = st.coord_system;
  for (int system = 1; system <= 9; ++system) {
    CoordSystemReport& report = out.systems[static_cast<std::size_t>(system - 1)];
    report.index = system;
    report.origin = interp_->coord_system_origin(system, &report.rotation_deg);
  }
  out.g92 = st.g92_offset;
  return out;
}

void Task::set_offsets(int system, const interp::Pose& origin, std::uint32_t axes,
                       std::optional<double> rotation_deg) {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI command is running");
  if (auto problem = interp_->set_coord_system_origin(system, origin, axes, rotation_deg)) {
    throw TaskError(TaskErrorKind::bad_value, *problem);
  }
  // Saved before the answer; when the file cannot be written the old origin is put back.
  if (const std::string error = save_setup_files(); !error.empty()) {
    throw TaskError(TaskErrorKind::save_failed,
                    error + "; " + coord_system_name(system) + " is unchanged");
  }
  events_.add("info", "offsets", coord_system_name(system) + " origin changed");
}

}  // namespace cncd::daemon
