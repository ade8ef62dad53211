#include "status_json.hpp"

#include <string>

namespace cncd::daemon {

using nlohmann::json;

// The program object of status.get but its two optional numbers.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(ProgramReport, path, opening, line, total_lines, dialect,
                                   progress, stepping, moves, elapsed_s, motion_s, remaining_reason,
                                   result, error)

namespace {

const char* motion_state_name(motion::MotionState state) {
  static constexpr const char* kNames[] = {"idle",     "moving", "pausing", "paused",
                                           "stopping", "homing", "jogging"};
  return enum_name(state, kNames);
}

const char* mode_name(Mode mode) {
  static constexpr const char* kNames[] = {"manual", "auto", "mdi"};
  return enum_name(mode, kNames);
}

const char* units_name(const config::MachineConfig& config) {
  return config.linear_units == config::LinearUnits::inch ? "inch" : "mm";
}

// {"x": 1.5, "y": 0, "z": -2} for the machine's axes.
template <typename Pose>
json axes_object(const config::MachineConfig& config, const Pose& pose) {
  json out = json::object();
  for (std::size_t i = 0; i < config::kAxisLetters.size() && i < pose.size(); ++i) {
    if (!config.axes[i].present) continue;
    const char letter = static_cast<char>(config::kAxisLetters[i] - 'A' + 'a');
    out[std::string(1, letter)] = pose[i];
  }
  return out;
}

json joints_array(const std::vector<JointReport>& joints) {
  json out = json::array();
  for (const JointReport& joint : joints) {
    out.push_back({{"homed", joint.homed},
                   {"fault", joint.fault},
                   {"min_limit", joint.io.min_limit},
                   {"max_limit", joint.io.max_limit},
                   {"home_switch", joint.io.home_switch},
                   {"at_min_soft_limit", joint.io.at_min_soft_limit},
                   {"at_max_soft_limit", joint.io.at_max_soft_limit},
                   {"driver", std::string(joint.io.driver)},
                   {"enabled", joint.io.enabled},
                   {"drive_fault", joint.io.drive_fault},
                   {"stale", joint.io.stale},
                   {"commanded", joint.commanded},
                   {"actual", joint.actual}});
  }
  return out;
}

json spindle_object(const SpindleReport& sp) {
  json out{{"direction", sp.direction},
           {"speed", sp.speed},
           {"programmed_speed", sp.programmed_speed},
           {"override", sp.override_ratio},
           {"override_enabled", sp.override_enabled},
           {"enabled", sp.enabled},
           {"commanded_rpm", sp.commanded_rpm},
           {"actual_rpm", sp.actual_rpm},
           {"at_speed", sp.at_speed}};
  if (sp.position) out["position"] = *sp.position;
  out["css"] = sp.css_max_rpm ? json{{"max_rpm", *sp.css_max_rpm}} : json(nullptr);
  out["orient"] =
      sp.orient.empty() ? json(nullptr) : json{{"state", sp.orient}, {"angle", sp.orient_angle}};
  return out;
}

json bits_array(std::uint32_t bits) {
  json out = json::array();
  for (int i = 0; i < 32; ++i)
    out.push_back(((bits >> i) & 1u) != 0);
  return out;
}

json io_object(const IoReport& io) {
  return json{{"douts", bits_array(io.douts)},
              {"aouts", io.aouts},
              {"dins", bits_array(io.dins)},
              {"ains", io.ains}};
}

json wait_object(const WaitReport& w) {
  if (w.kind.empty()) return nullptr;
  json out{{"kind", w.kind}, {"message", w.message}, {"since", w.since_s}};
  if (w.kind == "tool_change") out["tool"] = w.tool;
  return out;
}

json program_object(const ProgramReport& p) {
  json out = p;
  out["estimated_s"] = optional_number(p.estimated_s);
  out["remaining_s"] = optional_number(p.remaining_s);
  return out;
}

json rt_object(const motion::RtStats& rt) {
  json below = json::array();
  for (std::size_t i = 0; i < motion::kWakeEdgesUs.size(); ++i)
    below.push_back({{"us", motion::kWakeEdgesUs[i]}, {"count", rt.wake_error_below[i]}});
  return {{"cycles", rt.cycles},
          {"overruns", rt.overruns},
          {"wake_error_p50_ns", rt.wake_error_p50_ns},
          {"wake_error_p99_ns", rt.wake_error_p99_ns},
          {"wake_error_p999_ns", rt.wake_error_p999_ns},
          {"wake_error_max_ns", rt.wake_error_max_ns},
          {"wake_error_below", below},
          {"wake_error_count", rt.wake_error_count},
          {"wake_error_sum_ns", rt.wake_error_sum_ns},
          {"modbus_errors", rt.modbus_errors},
          {"realtime", rt.realtime},
          {"memory_locked", rt.memory_locked}};
}

// An axis index as its letter ("X"), null for none.
json axis_letter(int axis) {
  return axis >= 0 && static_cast<std::size_t>(axis) < config::kAxisLetters.size()
             ? json(std::string(1, config::kAxisLetters[static_cast<std::size_t>(axis)]))
             : json(nullptr);
}

json manual_holder_object(const std::optional<ManualHolder>& holder) {
  if (!holder) return nullptr;
  // A joint-mode jog's target counts from config::kMaxAxes (motion::kJointJogBase).
  const bool joint = holder->axis >= config::kMaxAxes;
  return {{"by", holder->by},
          {"panel", holder->panel},
          {"axis", axis_letter(holder->axis)},
          {"joint", joint ? json(holder->axis - config::kMaxAxes) : json(nullptr)}};
}

// {"KEY": true, ...} of the panel's inputs or lights.
json flags_object(const std::vector<std::pair<std::string, bool>>& flags) {
  json out = json::object();
  for (const auto& [key, on] : flags)
    out[key] = on;
  return out;
}

json panel_object(const std::optional<PanelReport>& panel) {
  if (!panel) return nullptr;
  return json{{"inputs", flags_object(panel->inputs)},
              {"mpg",
               {{"axis", axis_letter(panel->mpg_axis)},
                {"step", panel->mpg_step},
                {"counts", panel->mpg_counts},
                {"jogging", panel->mpg_jogging}}},
              {"door", panel->door},
              {"single_block", panel->single_block},
              {"optional_stop", panel->optional_stop},
              {"block_delete", panel->block_delete},
              {"lights", flags_object(panel->lights)}};
}

json tcp_object(const std::optional<TcpReport>& tcp) {
  if (!tcp) return nullptr;
  return json{{"programmed", tcp->programmed}, {"motion", tcp->motion}};
}

json tool_tip_object(const config::MachineConfig& config, const std::optional<TcpReport>& tcp) {
  if (!tcp) return nullptr;
  return json{{"commanded", axes_object(config, tcp->tip_commanded)},
              {"actual", axes_object(config, tcp->tip_actual)}};
}

}  // namespace

json optional_number(const std::optional<double>& value) {
  return value ? json(*value) : json(nullptr);
}

json status_json(const TaskStatus& s, const config::MachineConfig& config, std::size_t clients) {
  json homed = json::array();
  json joint_fault = json::array();
  for (const JointReport& joint : s.joints) {
    homed.push_back(joint.homed);
    joint_fault.push_back(joint.fault);
  }
  json tool_entry = nullptr;
  if (s.tool.entry)
    tool_entry = {{"diameter", s.tool.entry->diameter}, {"comment", s.tool.entry->comment}};
  return json{
      {"state", machine_state_name(s.machine)},
      {"exec", exec_state_name(s.exec)},
      {"mode", mode_name(s.mode)},
      {"motion", motion_state_name(s.motion)},
      {"units", units_name(config)},
      {"homed", homed},
      {"joint_fault", joint_fault},
      {"joints", joints_array(s.joints)},
      {"fault", s.fault},
      {"position",
       {{"commanded", axes_object(config, s.commanded)},
        {"actual", axes_object(config, s.actual)}}},
      {"tool_tip", tool_tip_object(config, s.tcp)},
      {"tcp", tcp_object(s.tcp)},
      {"position_restored", s.position_restored},
      {"work_position",
       {{"commanded", axes_object(config, s.work_commanded)},
        {"actual", axes_object(config, s.work_actual)}}},
      {"diameter_mode", s.diameter_mode},
      {"velocity", s.velocity},
      {"distance_to_go", s.distance_to_go},
      {"axes_to_go", axes_object(config, s.axes_to_go)},
      {"overrides",
       {{"feed", s.feed_override},
        {"rapid", s.rapid_override},
        {"spindle", s.spindle.override_ratio}}},
      {"program", program_object(s.program)},
      {"spindle", spindle_object(s.spindle)},
      {"coolant", {{"mist", s.mist}, {"flood", s.flood}}},
      {"io", io_object(s.io)},
      {"wait", wait_object(s.wait)},
      {"probe",
       {{"tripped", s.probe.contact},
        {"probing", s.probe.probing},
        {"last_result", s.probe.last_tripped ? json(*s.probe.last_tripped ? 1 : 0) : json(nullptr)},
        {"last_position",
         s.probe.last_tripped ? axes_object(config, s.probe.last_position) : json(nullptr)}}},
      {"sync", s.sync.mode.empty() ? json(nullptr)
                                   : json{{"mode", s.sync.mode},
                                          {"phase", s.sync.phase},
                                          {"per_rev", s.sync.per_rev},
                                          {"progress", s.sync.progress}}},
      {"pause_wait", s.pause_wait.kind.empty() ? json(nullptr)
                                               : json{{"kind", s.pause_wait.kind},
                                                      {"line", s.pause_wait.line},
                                                      {"message", s.pause_wait.message}}},
      {"tool",
       {{"number", s.tool.number},
        {"prepared", s.tool.prepared},
        {"length_offset", axes_object(config, s.tool.length_offset)},
        {"entry", tool_entry}}},
      {"offsets",
       {{"coord_system", coord_system_name(s.offsets.coord_system)},
        {"index", s.offsets.coord_system},
        {"g5x", axes_object(config, s.offsets.g5x)},
        {"rotation", s.offsets.rotation_deg},
        {"g92", axes_object(config, s.offsets.g92)}}},
      {"gcodes", s.gcodes},
      {"mcodes", s.mcodes},
      {"feed_rate", s.feed_rate},
      {"rt", rt_object(s.rt)},
      {"panel", panel_object(s.panel)},
      {"manual_holder", manual_holder_object(s.manual_holder)},
      {"clients", clients},
  };
}

json tool_list_json(const std::vector<interp::ToolEntry>& tools,
                    const config::MachineConfig& config) {
  json list = json::array();
  for (const auto& tool : tools) {
    list.push_back({{"number", tool.number},
                    {"pocket", tool.pocket},
                    {"offset", axes_object(config, tool.offset)},
                    {"diameter", tool.diameter},
                    {"front_angle", tool.front_angle},
                    {"back_angle", tool.back_angle},
                    {"orientation", tool.orientation},
                    {"comment", tool.comment}});
  }
  return json{{"path", config.tool_table.string()}, {"units", units_name(config)}, {"tools", list}};
}

json offsets_json(const OffsetsReport& offsets, const config::MachineConfig& config) {
  json systems = json::array();
  for (const CoordSystemReport& system : offsets.systems) {
    systems.push_back({{"name", coord_system_name(system.index)},
                       {"index", system.index},
                       {"origin", axes_object(config, system.origin)},
                       {"rotation", system.rotation_deg}});
  }
  return json{{"active", coord_system_name(offsets.active)},
              {"units", units_name(config)},
              {"systems", systems},
              {"g92", axes_object(config, offsets.g92)}};
}

json event_json(const Event& event) {
  json out = {{"seq", event.seq},
              {"time", event.time},
              {"level", event.level},
              {"kind", event.kind},
              {"message", event.message}};
  if (!event.by.empty()) out["by"] = event.by;
  if (!event.code.empty()) out["code"] = event.code;
  return out;
}

json events_json(const std::vector<Event>& events) {
  json out = json::array();
  for (const auto& event : events)
    out.push_back(event_json(event));
  return out;
}

}  // namespace cncd::daemon
