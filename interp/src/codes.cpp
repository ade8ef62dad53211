#include "codes.hpp"

#include <array>

namespace cncd::interp {
namespace {

struct GEntry {
  int code;
  GGroup group;
  bool supported;
};

// Every G code LinuxCNC 2.9 knows. Unsupported ones are listed so that they are reported as
// "not supported" rather than as unknown.
constexpr std::array kGCodes{
    GEntry{0, GGroup::motion, true},          GEntry{10, GGroup::motion, true},
    GEntry{20, GGroup::motion, true},         GEntry{30, GGroup::motion, true},
    GEntry{40, GGroup::non_modal, true},      GEntry{50, GGroup::motion, true},
    GEntry{51, GGroup::motion, true},         GEntry{52, GGroup::motion, true},
    GEntry{53, GGroup::non_modal, true},      GEntry{70, GGroup::lathe_diameter, true},
    GEntry{80, GGroup::lathe_diameter, true}, GEntry{100, GGroup::non_modal, true},
    GEntry{170, GGroup::plane, true},         GEntry{171, GGroup::plane, true},
    GEntry{180, GGroup::plane, true},         GEntry{181, GGroup::plane, true},
    GEntry{190, GGroup::plane, true},         GEntry{191, GGroup::plane, true},
    GEntry{200, GGroup::units, true},         GEntry{210, GGroup::units, true},
    GEntry{280, GGroup::non_modal, true},     GEntry{281, GGroup::non_modal, true},
    GEntry{300, GGroup::non_modal, true},     GEntry{301, GGroup::non_modal, true},
    GEntry{330, GGroup::motion, true},        GEntry{331, GGroup::motion, true},
    GEntry{382, GGroup::motion, true},        GEntry{383, GGroup::motion, true},
    GEntry{384, GGroup::motion, true},        GEntry{385, GGroup::motion, true},
    GEntry{400, GGroup::cutter_comp, true},   GEntry{410, GGroup::cutter_comp, true},
    GEntry{411, GGroup::cutter_comp, true},   GEntry{420, GGroup::cutter_comp, true},
    GEntry{421, GGroup::cutter_comp, true},   GEntry{430, GGroup::tool_length, true},
    GEntry{431, GGroup::tool_length, true},   GEntry{432, GGroup::tool_length, true},
    GEntry{490, GGroup::tool_length, true},   GEntry{520, GGroup::non_modal, true},
    GEntry{530, GGroup::non_modal, true},     GEntry{540, GGroup::coord_system, true},
    GEntry{550, GGroup::coord_system, true},  GEntry{560, GGroup::coord_system, true},
    GEntry{570, GGroup::coord_system, true},  GEntry{580, GGroup::coord_system, true},
    GEntry{590, GGroup::coord_system, true},  GEntry{591, GGroup::coord_system, true},
    GEntry{592, GGroup::coord_system, true},  GEntry{593, GGroup::coord_system, true},
    GEntry{610, GGroup::path_control, true},  GEntry{611, GGroup::path_control, true},
    GEntry{640, GGroup::path_control, true},  GEntry{700, GGroup::motion, true},
    GEntry{710, GGroup::motion, true},        GEntry{711, GGroup::motion, true},
    GEntry{712, GGroup::motion, true},        GEntry{720, GGroup::motion, true},
    GEntry{721, GGroup::motion, true},        GEntry{722, GGroup::motion, true},
    GEntry{730, GGroup::motion, true},        GEntry{740, GGroup::motion, true},
    GEntry{760, GGroup::motion, true},        GEntry{800, GGroup::motion, true},
    GEntry{810, GGroup::motion, true},        GEntry{820, GGroup::motion, true},
    GEntry{830, GGroup::motion, true},        GEntry{840, GGroup::motion, true},
    GEntry{850, GGroup::motion, true},        GEntry{860, GGroup::motion, true},
    GEntry{870, GGroup::motion, true},        GEntry{880, GGroup::motion, true},
    GEntry{890, GGroup::motion, true},        GEntry{900, GGroup::distance, true},
    GEntry{901, GGroup::arc_distance, true},  GEntry{910, GGroup::distance, true},
    GEntry{911, GGroup::arc_distance, true},  GEntry{920, GGroup::non_modal, true},
    GEntry{921, GGroup::non_modal, true},     GEntry{922, GGroup::non_modal, true},
    GEntry{923, GGroup::non_modal, true},     GEntry{930, GGroup::feed_mode, true},
    GEntry{940, GGroup::feed_mode, true},     GEntry{950, GGroup::feed_mode, true},
    GEntry{960, GGroup::spindle_mode, true},  GEntry{970, GGroup::spindle_mode, true},
    GEntry{980, GGroup::retract, true},       GEntry{990, GGroup::retract, true},
};

// Direct lookup: G codes run from 0 to 99.9, so an array indexed by code covers them all.
constexpr std::array<CodeInfo, 1000> make_g_index() {
  std::array<CodeInfo, 1000> index{};
  for (const auto& entry : kGCodes) {
    index[static_cast<std::size_t>(entry.code)] =
        CodeInfo{static_cast<std::int8_t>(entry.group), entry.supported};
  }
  return index;
}
constexpr auto kGIndex = make_g_index();

}  // namespace

CodeInfo g_code_info(int code) {
  if (code < 0 || code >= static_cast<int>(kGIndex.size())) return {};
  return kGIndex[static_cast<std::size_t>(code)];
}

CodeInfo m_code_info(int code) {
  // M codes first .. last, their group and whether they are supported. M70-M73 share the
  // spindle group with M3-M5 and M19, as in LinuxCNC.
  struct Codes {
    int first;
    int last;
    MGroup group;
    bool supported;
  };
  static constexpr Codes kCodes[] = {
      {0, 2, MGroup::stopping, true},      {30, 30, MGroup::stopping, true},
      {60, 60, MGroup::stopping, true},    {3, 5, MGroup::spindle, true},
      {19, 19, MGroup::spindle, true},     {6, 6, MGroup::tool_change, true},
      {61, 61, MGroup::tool_change, true}, {7, 9, MGroup::coolant, true},
      {48, 53, MGroup::overrides, true},   {62, 68, MGroup::io, true},
      {70, 73, MGroup::spindle, true},     {98, 99, MGroup::stopping, true},
      {100, 199, MGroup::user, true},      {428, 429, MGroup::user, true},
  };
  for (const Codes& codes : kCodes) {
    if (code >= codes.first && code <= codes.last) {
      return CodeInfo{static_cast<std::int8_t>(codes.group), codes.supported};
    }
  }
  return {};
}

}  // namespace cncd::interp
