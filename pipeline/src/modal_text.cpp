#include "cncd/pipeline/modal_text.hpp"

#include <cstdio>

#include "number_text.hpp"

namespace cncd::pipeline {
namespace {

std::string pose(const interp::Pose& p) {
  std::string out;
  for (std::size_t a = 0; a < p.size() && a < 3; ++a)
    out += std::string(a > 0 ? " " : "") + "XYZ"[a] + fixed4(p[a]);
  return out;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words)
    out += (out.empty() ? "" : " ") + w;
  return out;
}

std::string move_text(const motion::Move& m, bool inch) {
  using Kind = motion::Move::Kind;
  using Action = motion::IoAction::Kind;
  const auto to = [&] {
    std::string out;
    for (std::size_t a = 0; a < m.end.size(); ++a) {
      if (a >= 3 && m.end[a] == 0) continue;
      out += std::string(" ") + "XYZABCUVW"[a] + fixed4(m.end[a]);
    }
    return out;
  };
  switch (m.kind) {
    case Kind::traverse:
      return "rapid to" + to();
    case Kind::feed:
    case Kind::arc:
      return "feed to" + to() + " at " + fixed4(m.feed * 60) + (inch ? " in/min" : " mm/min");
    case Kind::dwell:
      return "dwell " + fixed4(m.dwell_s) + " s";
    case Kind::action:
      break;
  }
  const motion::IoAction& a = m.action;
  switch (a.kind) {
    case Action::spindle:
      return a.direction == 0 ? "spindle stop"
                              : std::string("spindle ") + (a.direction > 0 ? "M3 " : "M4 ") +
                                    (a.css_max_rpm > 0 ? "G96" : fixed4(a.rpm) + " rpm");
    case Action::coolant:
      return std::string("coolant ") + (a.flood ? "flood" : "") + (a.flood && a.mist ? "+" : "") +
             (a.mist ? "mist" : "") + (!a.flood && !a.mist ? "off" : "");
    case Action::wait_at_speed:
      return "wait for the spindle at speed";
    case Action::hold:
      return a.hold == motion::IoAction::Hold::tool_change ? "wait for the tool change" : "wait";
    default:
      return "action";
  }
}

}  // namespace

std::string code_name(char letter, int code) {
  std::string out(1, letter);
  out += std::to_string(code / 10);
  if (code % 10 != 0) out += "." + std::to_string(code % 10);
  return out;
}

std::vector<std::string> active_g_codes(const interp::InterpState& state) {
  std::vector<std::string> out;
  for (std::size_t i = 1; i < state.gcodes.size(); ++i) {
    if (state.gcodes[i] >= 0) out.push_back(code_name('G', state.gcodes[i]));
  }
  return out;
}

std::vector<std::string> active_m_codes(const interp::InterpState& state) {
  std::vector<std::string> out;
  for (std::size_t i = 1; i < state.mcodes.size(); ++i) {
    if (state.mcodes[i] >= 0) out.push_back("M" + std::to_string(state.mcodes[i]));
  }
  return out;
}

std::string describe_from_line(const FromLineReport& report, bool inch) {
  const interp::InterpState& s = report.state;
  std::string out = "from line " + std::to_string(report.line) + ":\n";
  if (!report.reached) return out + "  the program ends before that line\n";
  out += "  modal: " + join(active_g_codes(s)) + " " + join(active_m_codes(s)) + "\n";
  out += "  F" + fixed4(s.feed_rate) + " S" + fixed4(s.speed) + " T" +
         std::to_string(s.tool_in_spindle) + "\n";
  const int system = s.coord_system;
  out += "  " + code_name('G', system < 7 ? 530 + 10 * system : 584 + system) + " origin " +
         pose(s.g5x_offset) + ", G92 " + pose(s.g92_offset) + ", tool " + pose(s.tool_offset) +
         "\n";
  out += "  before the line (machine coordinates):\n";
  if (report.lead_in.empty()) out += "    nothing\n";
  for (const auto& move : report.lead_in)
    out += "    " + move_text(move, inch) + "\n";
  return out;
}

}  // namespace cncd::pipeline
