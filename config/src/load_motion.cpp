#include <algorithm>
#include <set>
#include <sstream>
#include <vector>

#include "kins_map.hpp"
#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

std::string axis_section(char letter) {
  return std::string("AXIS_") + letter;
}
std::string joint_section(int joint) {
  return "JOINT_" + std::to_string(joint);
}
bool is_linear_axis(char letter) {
  return std::string_view("XYZUVW").find(letter) != std::string_view::npos;
}

void load_axis(TypedReader& r, MachineConfig& c, char letter) {
  const std::string s = axis_section(letter);
  AxisConfig& axis = c.axes[static_cast<std::size_t>(axis_index(letter))];
  axis.present = c.coordinates.find(letter) != std::string::npos;
  axis.source = r.where(s, "");
  if (!r.ini().has_section(s)) {
    if (axis.present) {
      r.warning(s, "",
                "section missing; LinuxCNC defaults used (no soft limits, "
                "MAX_VELOCITY 1, MAX_ACCELERATION 1)");
    }
  } else {
    for (const auto* key : {"MAX_VELOCITY", "MAX_ACCELERATION"}) {
      if (!r.given(s, key)) r.warning(s, key, "not given; LinuxCNC default 1 used");
    }
  }
  if (const auto v = r.real(s, "MIN_LIMIT")) axis.min_limit = *v;
  if (const auto v = r.real(s, "MAX_LIMIT")) axis.max_limit = *v;
  if (const auto v = r.real(s, "MAX_VELOCITY")) axis.max_velocity = *v;
  if (const auto v = r.real(s, "MAX_ACCELERATION")) axis.max_acceleration = *v;
  if (const auto v = r.real(s, "MAX_JERK")) axis.max_jerk = *v;
}

void load_homing(TypedReader& r, const std::string& s, JointConfig& j) {
  if (const auto v = r.real(s, "HOME")) j.home = *v;
  if (const auto v = r.real(s, "HOME_OFFSET")) j.home_offset = *v;
  if (const auto v = r.real(s, "HOME_SEARCH_VEL")) j.home_search_vel = *v;
  if (const auto v = r.real(s, "HOME_LATCH_VEL")) j.home_latch_vel = *v;
  if (const auto v = r.real(s, "HOME_FINAL_VEL")) j.home_final_vel = *v;
  j.home_use_index = r.boolean(s, "HOME_USE_INDEX").value_or(false);
  j.home_index_no_encoder_reset = r.boolean(s, "HOME_INDEX_NO_ENCODER_RESET").value_or(false);
  j.home_ignore_limits = r.boolean(s, "HOME_IGNORE_LIMITS").value_or(false);
  j.home_is_shared = r.boolean(s, "HOME_IS_SHARED").value_or(false);
  j.volatile_home = r.boolean(s, "VOLATILE_HOME").value_or(false);
  j.locking_indexer = r.boolean(s, "LOCKING_INDEXER").value_or(false);
  j.home_absolute_encoder = r.integer(s, "HOME_ABSOLUTE_ENCODER").value_or(0) != 0;
  j.home_sequence = -1;
  if (const auto v = r.integer(s, "HOME_SEQUENCE")) {
    j.home_sequence = static_cast<int>(*v < 0 ? -*v : *v);
    j.home_sequence_sync = *v < 0;
  }
}

JointConfig load_joint(TypedReader& r, const MachineConfig& c, int index, char letter) {
  const std::string s = joint_section(index);
  JointConfig j;
  j.axis = letter;
  j.source = r.where(s, "");
  if (r.ini().has_section(s)) {
    for (const auto* key : {"MAX_VELOCITY", "MAX_ACCELERATION"}) {
      if (!r.given(s, key)) r.warning(s, key, "not given; LinuxCNC default 1 used");
    }
  }
  if (const auto v = r.choice(s, "TYPE")) {
    j.type = *v == "ANGULAR" ? JointType::angular : JointType::linear;
  }
  const AxisConfig* axis = letter != '\0' ? &c.axis(letter) : nullptr;
  j.min_limit = r.real(s, "MIN_LIMIT").value_or(axis != nullptr ? axis->min_limit : -1e99);
  j.max_limit = r.real(s, "MAX_LIMIT").value_or(axis != nullptr ? axis->max_limit : 1e99);
  if (const auto v = r.real(s, "MAX_VELOCITY")) j.max_velocity = *v;
  if (const auto v = r.real(s, "MAX_ACCELERATION")) j.max_acceleration = *v;
  if (const auto v = r.real(s, "FERROR")) j.ferror = *v;
  j.min_ferror = r.real(s, "MIN_FERROR").value_or(j.ferror);
  if (const auto v = r.real(s, "BACKLASH")) j.backlash = *v;
  load_homing(r, s, j);
  if (const auto v = r.real(s, "SCALE")) j.scale = *v;
  if (const auto v = r.real(s, "INPUT_SCALE")) j.input_scale = *v;
  if (const auto v = r.real(s, "OUTPUT_SCALE")) j.output_scale = *v;
  if (const auto v = r.choice(s, "DRIVER")) j.driver = *v;
  return j;
}

// A joint without its [JOINT_n] section runs on LinuxCNC's made-up defaults (1 unit/s, no
// limits of its own). Shipped lathes keep such a joint for an axis they do not have (trivkins
// without coordinates=, joint 1 = Y); a joint that moves an axis of the machine must be
// configured, and a [JOINT_n] numbered past JOINTS is then most likely the one meant for it.
void check_joint_section(TypedReader& r, const MachineConfig& c, int index, char letter) {
  const std::string s = joint_section(index);
  if (r.ini().has_section(s)) return;
  if (letter == '\0' || c.coordinates.find(letter) == std::string::npos) {
    r.warning(s, "",
              "section missing; LinuxCNC defaults used (MAX_VELOCITY 1, "
              "MAX_ACCELERATION 1)");
    return;
  }
  std::string beyond;
  for (int n = c.joint_count; n < kMaxJoints; ++n) {
    if (r.ini().has_section(joint_section(n))) beyond += " [" + joint_section(n) + "]";
  }
  r.problem(
      "KINS", "JOINTS",
      "JOINTS = " + std::to_string(c.joint_count) + ", but joint " + std::to_string(index) +
          " (axis " + letter + ") has no [" + s + "] section" +
          (beyond.empty() ? "" : "; the file has" + beyond + " instead, which JOINTS leaves out"));
}

// Homing waits for joints that have no section after the last [JOINT_n] and drive no axis of
// COORDINATES for ever: they are refused together, by number.
void refuse_unconfigured_joints(TypedReader& r, const MachineConfig& c,
                                const std::vector<int>& joints, int last_section) {
  std::string list;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const char* separator = i == 0 ? "" : i + 1 == joints.size() ? " and " : ", ";
    list += separator + std::to_string(joints[i]);
  }
  const std::string last =
      last_section < 0
          ? "the file has none): give each joint its section"
          : "the last is [" + joint_section(last_section) +
                "]): set JOINTS = " + std::to_string(last_section + 1 + c.extra_joints) +
                ", or give each joint its section";
  r.problem("KINS", "JOINTS",
            "JOINTS = " + std::to_string(c.joint_count) + ", but joint" +
                (joints.size() == 1 ? " " : "s ") + list + (joints.size() == 1 ? " has" : " have") +
                " no [JOINT_n] section (" + last);
}

// Path limits not given in [TRAJ] follow the axes, as LinuxCNC lets the axis limits apply.
void derive_traj_limits(TypedReader& r, MachineConfig& c) {
  double fastest = 0;
  double quickest = 0;
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    if (!c.axes[i].present || !is_linear_axis(kAxisLetters[i])) continue;
    fastest = std::max(fastest, c.axes[i].max_velocity);
    quickest = std::max(quickest, c.axes[i].max_acceleration);
  }
  if (c.max_linear_velocity == 0) c.max_linear_velocity = fastest > 0 ? fastest : 1.0;
  if (c.max_linear_acceleration == 0) c.max_linear_acceleration = quickest > 0 ? quickest : 1.0;
  if (c.default_linear_velocity == 0) c.default_linear_velocity = 1.0;
  if (c.default_linear_acceleration == 0) c.default_linear_acceleration = c.max_linear_acceleration;
  if (c.default_linear_velocity > c.max_linear_velocity) {
    r.warning("TRAJ", "DEFAULT_LINEAR_VELOCITY",
              format_number(c.default_linear_velocity) + " is above MAX_LINEAR_VELOCITY " +
                  format_number(c.max_linear_velocity) + "; lowered to it");
    c.default_linear_velocity = c.max_linear_velocity;
  }
}

}  // namespace

// A corexy motor's soft limits: the range it covers while X and Y stay within theirs (joint 0 =
// X + Y, joint 1 = X - Y) when its [JOINT_n] gives none, and never narrower, since moves are
// checked against the axes' limits (as a trivkins joint's must include its axis's).
void corexy_motor_limits(TypedReader& r, const MachineConfig& c, int index, JointConfig& j) {
  const AxisConfig& x = c.axis('X');
  const AxisConfig& y = c.axis('Y');
  const std::string s = joint_section(index);
  const double low = index == 0 ? x.min_limit + y.min_limit : x.min_limit - y.max_limit;
  const double high = index == 0 ? x.max_limit + y.max_limit : x.max_limit - y.min_limit;
  const std::string motor = index == 0 ? "X + Y" : "X - Y";
  if (!r.given(s, "MIN_LIMIT")) {
    j.min_limit = low;
  } else if (j.min_limit > low && !r.failed(s, "MIN_LIMIT")) {
    r.problem(s, "MIN_LIMIT",
              format_number(j.min_limit) + " is narrower than the " + format_number(low) +
                  " that this motor (" + motor +
                  ") reaches within the X and Y limits; joint limits must include the axis limits");
  }
  if (!r.given(s, "MAX_LIMIT")) {
    j.max_limit = high;
  } else if (j.max_limit < high && !r.failed(s, "MAX_LIMIT")) {
    r.problem(s, "MAX_LIMIT",
              format_number(j.max_limit) + " is narrower than the " + format_number(high) +
                  " that this motor (" + motor +
                  ") reaches within the X and Y limits; joint limits must include the axis limits");
  }
}

void load_motion(TypedReader& r, MachineConfig& c) {
  const KinsChoice k = load_kinematics(r);
  c.kinematics = k.module.empty() ? c.kinematics : k.module;
  c.kinematics_args = k.args;
  const auto joints = r.integer("KINS", "JOINTS");
  if (!joints) {
    if (!r.given("KINS", "JOINTS")) r.problem("KINS", "JOINTS", "missing; the number of joints");
    return;
  }
  c.joint_count = static_cast<int>(*joints);
  if (c.extra_joints >= c.joint_count) {
    r.problem("EMCMOT", "EMCMOT",
              "num_extrajoints=" + std::to_string(c.extra_joints) +
                  " leaves no joint for the axes (JOINTS = " + std::to_string(c.joint_count) + ")");
    c.extra_joints = 0;
  }
  if (!k.ok) return;
  const std::string map = joint_map(r, k, c);
  load_table_rotary(r, k, c);

  for (const char letter : kAxisLetters) {
    const bool driven = map.find(letter) != std::string::npos;
    const bool present = c.coordinates.find(letter) != std::string::npos;
    if (present || (driven && r.ini().has_section(axis_section(letter)))) load_axis(r, c, letter);
  }
  c.joints.clear();
  int last_section = -1;
  for (int n = 0; n < kMaxJoints; ++n) {
    if (r.ini().has_section(joint_section(n))) last_section = n;
  }
  std::vector<int> unconfigured;
  for (int index = 0; index < c.joint_count; ++index) {
    const char letter =
        index < static_cast<int>(map.size()) ? map[static_cast<std::size_t>(index)] : '\0';
    const bool motor = k.corexy && index < 2 && index < c.joint_count - c.extra_joints;
    const bool drives_axis =
        motor || (letter != '\0' && c.coordinates.find(letter) != std::string::npos);
    if (index > last_section && index < c.joint_count - c.extra_joints && !drives_axis) {
      // No section here nor after it: JOINTS counts joints the machine does not have.
      unconfigured.push_back(index);
      c.joints.push_back(load_joint(r, c, index, letter));
      continue;
    }
    check_joint_section(r, c, index, motor ? "XY"[index] : letter);
    if (motor) {
      c.joints.push_back(load_joint(r, c, index, letter));
      corexy_motor_limits(r, c, index, c.joints.back());
      continue;
    }
    if (letter == '\0' && index < c.joint_count - c.extra_joints) {
      r.warning(joint_section(index), "", "joint is driven by no axis");
    } else if (letter != '\0' && c.coordinates.find(letter) == std::string::npos) {
      r.warning(
          joint_section(index), "",
          std::string("joint drives axis ") + letter + ", which is not in [TRAJ] COORDINATES");
    }
    c.joints.push_back(load_joint(r, c, index, letter));
  }
  if (!unconfigured.empty()) refuse_unconfigured_joints(r, c, unconfigured, last_section);
  derive_traj_limits(r, c);
}

}  // namespace cncd::config
