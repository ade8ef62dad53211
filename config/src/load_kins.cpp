// [KINS] KINEMATICS: the kinematics module, its arguments and the joint map it gives.
#include <algorithm>
#include <array>
#include <set>
#include <sstream>
#include <string_view>

#include "kins_map.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kSupported =
    "cncd supports trivkins, corexykins, xyzac-trt-kins and xyzbc-trt-kins";

// LinuxCNC's other kinematics modules (man 9 kins): known, not (yet) cncd's.
constexpr std::array<std::string_view, 14> kLinuxCncModules = {
    "genhexkins", "genserkins",     "lineardeltakins", "maxkins",    "pentakins",
    "pumakins",   "rosekins",       "rotarydeltakins", "rotatekins", "scarakins",
    "tripodkins", "xyzab_tdr_kins", "5axiskins",       "millturn"};

// trivkins coordinates=LETTERS: false (with a problem) when one is no axis letter.
bool read_coordinates(TypedReader& r, const std::string& value, KinsChoice& k) {
  for (const char ch : value) {
    if (axis_index(ch) < 0) {
      r.problem("KINS", "KINEMATICS",
                "coordinates=" + printable(value) + ": '" + printable(std::string(1, ch)) +
                    "' is not an axis letter");
      return false;
    }
  }
  k.coordinates = to_upper(value);
  return true;
}

// "Y is" or "X and Y are": the letters written more than once.
std::string repeated_letters(const std::string& letters) {
  std::string found;
  for (const char letter : kAxisLetters) {
    if (std::count(letters.begin(), letters.end(), letter) > 1) found += letter;
  }
  std::string text;
  for (std::size_t i = 0; i < found.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == found.size() ? " and " : ", ") + std::string(1, found[i]);
  }
  return text + (found.size() == 1 ? " is" : " are");
}

// With coordinates= the joints are trivkins', and [TRAJ] COORDINATES only names the axes: a
// letter it repeats more often than trivkins gives that axis joints is no gantry.
void check_repeats_match_kinematics(TypedReader& r, const KinsChoice& k,
                                    const std::string& coordinates) {
  for (const char letter : kAxisLetters) {
    const auto written = std::count(coordinates.begin(), coordinates.end(), letter);
    const auto joints = std::count(k.coordinates.begin(), k.coordinates.end(), letter);
    if (written < 2 || joints >= written) continue;
    r.problem("TRAJ", "COORDINATES",
              std::string(1, letter) + " is written " + std::to_string(written) +
                  " times, but trivkins coordinates=" + k.coordinates + " drives it with " +
                  std::to_string(joints) + " joint" + (joints == 1 ? "" : "s") +
                  "; a gantry repeats the letter in both");
  }
}

std::string trivkins_map(TypedReader& r, const KinsChoice& k, const MachineConfig& c) {
  const std::string jstr = "JOINTS = " + std::to_string(c.joint_count);
  const int kinematic_joints = c.joint_count - c.extra_joints;
  const std::set<char> distinct(c.coordinates.begin(), c.coordinates.end());
  std::string map;
  if (!k.coordinates.empty()) {
    map = k.coordinates;
    if (static_cast<int>(map.size()) > kinematic_joints) {
      r.problem("KINS", "JOINTS",
                jstr + " is too few: trivkins coordinates=" + map + " needs " +
                    std::to_string(map.size() + c.extra_joints) + " joints");
    }
    check_repeats_match_kinematics(r, k, c.coordinates);
  } else if (distinct.size() != c.coordinates.size()) {
    map = c.coordinates;
    if (static_cast<int>(distinct.size()) == kinematic_joints) {
      // One joint an axis: the repeat cannot be a gantry, it is a slip.
      r.problem("TRAJ", "COORDINATES",
                repeated_letters(c.coordinates) + " repeated, but a repeated letter is a " +
                    "gantry, one joint a letter (" + std::to_string(map.size()) + "), and " + jstr +
                    " gives each axis one joint; write each letter once, or JOINTS = " +
                    std::to_string(map.size() + c.extra_joints) + " for a gantry");
    } else if (static_cast<int>(map.size()) != kinematic_joints) {
      r.problem("KINS", "JOINTS",
                jstr + " does not match COORDINATES " + c.coordinates + ", which names " +
                    std::to_string(map.size()) + " joints");
    }
  } else {
    map = std::string(kAxisLetters);
    if (static_cast<int>(distinct.size()) > kinematic_joints) {
      r.problem("KINS", "JOINTS",
                jstr + " is too few for the " + std::to_string(distinct.size()) +
                    " axes of COORDINATES " + c.coordinates);
    }
  }
  return map;
}

std::string corexy_map(TypedReader& r, const MachineConfig& c) {
  const std::set<char> distinct(c.coordinates.begin(), c.coordinates.end());
  if (distinct.size() != c.coordinates.size()) {
    r.problem("TRAJ", "COORDINATES",
              repeated_letters(c.coordinates) +
                  " repeated, but corexykins drives each axis with its own joints and has no "
                  "gantry; write each letter once");
  }
  for (const char letter : {'X', 'Y'}) {
    if (distinct.count(letter) == 0) {
      r.problem("TRAJ", "COORDINATES",
                "COORDINATES " + c.coordinates + " has no " + letter +
                    ", but corexykins moves X and Y with joints 0 and 1");
    }
  }
  if (c.joint_count - c.extra_joints < 2) {
    r.problem("KINS", "JOINTS",
              "JOINTS = " + std::to_string(c.joint_count) +
                  " is too few: corexykins needs joints 0 and 1 for the X + Y and X - Y motors");
  }
  return std::string(2, '\0') + std::string(kAxisLetters.substr(2));
}

// xyzac-trt-kins and xyzbc-trt-kins: joints 0-4 are X, Y, Z, the tilting axis and C, as in
// LinuxCNC; each of them an axis of [TRAJ] COORDINATES, written once.
std::string table_rotary_map(TypedReader& r, const KinsChoice& k, const MachineConfig& c) {
  const std::string map = std::string("XYZ") + k.tilt + "C";
  const std::set<char> distinct(c.coordinates.begin(), c.coordinates.end());
  if (distinct.size() != c.coordinates.size()) {
    r.problem("TRAJ", "COORDINATES",
              repeated_letters(c.coordinates) + " repeated, but " + k.module +
                  " drives each axis with one joint and has no gantry; write each letter once");
  }
  for (const char letter : map) {
    if (distinct.count(letter) == 0) {
      r.problem("TRAJ", "COORDINATES",
                "COORDINATES " + c.coordinates + " has no " + letter + ", but " + k.module +
                    " moves " + map + " with joints 0 to 4");
    }
  }
  if (c.joint_count - c.extra_joints < 5) {
    r.problem("KINS", "JOINTS",
              "JOINTS = " + std::to_string(c.joint_count) + " is too few: " + k.module +
                  " needs joints 0 to 4 for " + map);
  }
  return map;
}

}  // namespace

void load_table_rotary(TypedReader& r, const KinsChoice& k, MachineConfig& c) {
  if (k.tilt == '\0') return;
  TableRotaryConfig& t = c.table_rotary;
  const auto read = [&](std::string_view key, double& into) {
    if (const auto value = r.real("KINS", key)) into = *value;
  };
  read("X_ROT_POINT", t.x_rot_point);
  read("Y_ROT_POINT", t.y_rot_point);
  read("Z_ROT_POINT", t.z_rot_point);
  read(k.tilt == 'A' ? "Y_OFFSET" : "X_OFFSET", k.tilt == 'A' ? t.y_offset : t.x_offset);
  read("Z_OFFSET", t.z_offset);
  read("TOOL_OFFSET", t.tool_offset);
  if (const auto tolerance = r.real("TRAJ", "TCP_TOLERANCE")) t.tcp_tolerance = *tolerance;
  const std::string_view other = k.tilt == 'A' ? "X_OFFSET" : "Y_OFFSET";
  if (r.given("KINS", other)) {
    r.warning("KINS", other,
              std::string(other) + " is not a parameter of " + k.module + "; ignored");
  }
}

KinsChoice load_kinematics(TypedReader& r) {
  KinsChoice k;
  const auto written = r.text("KINS", "KINEMATICS");
  if (!written) {
    r.problem("KINS", "KINEMATICS", "missing; write KINEMATICS = trivkins");
    return k;
  }
  std::istringstream words{std::string(strip_trailing_comment(*written))};
  words >> k.module;
  const std::string& module = k.module;  // case matters, as for LinuxCNC's loadrt
  if (module.empty()) {
    r.problem("KINS", "KINEMATICS", "no module named; write KINEMATICS = trivkins");
    return k;
  }
  k.corexy = module == "corexykins";
  if (module == "xyzac-trt-kins") k.tilt = 'A';
  if (module == "xyzbc-trt-kins") k.tilt = 'B';
  if (module != "trivkins" && !k.corexy && k.tilt == '\0') {
    const bool known = std::find(kLinuxCncModules.begin(), kLinuxCncModules.end(), module) !=
                       kLinuxCncModules.end();
    r.problem("KINS", "KINEMATICS",
              "kinematics '" + printable(k.module) +
                  (known ? "' is not supported; "
                         : "' is no kinematics module LinuxCNC or cncd "
                           "knows; ") +
                  std::string(kSupported));
    return k;
  }
  k.ok = true;
  std::string word;
  while (words >> word) {
    k.args += (k.args.empty() ? "" : " ") + word;
    const std::size_t equal = word.find('=');
    const std::string name = to_lower(word.substr(0, equal));
    const std::string value = equal == std::string::npos ? "" : word.substr(equal + 1);
    if (!k.corexy && k.tilt == '\0' && name == "coordinates") {
      if (!read_coordinates(r, value, k)) {
        k.ok = false;
        return k;
      }
    } else if (k.corexy || name != (k.tilt != '\0' ? "sparm" : "kinstype")) {
      r.warning("KINS", "KINEMATICS",
                "unknown " + module + " argument '" + printable(word) + "' ignored");
    }
  }
  return k;
}

std::string joint_map(TypedReader& r, const KinsChoice& k, MachineConfig& c) {
  std::string map = k.corexy         ? corexy_map(r, c)
                    : k.tilt != '\0' ? table_rotary_map(r, k, c)
                                     : trivkins_map(r, k, c);
  const int kinematic_joints = c.joint_count - c.extra_joints;
  if (static_cast<int>(map.size()) > kinematic_joints) map.resize(std::max(0, kinematic_joints));
  const std::set<char> distinct(c.coordinates.begin(), c.coordinates.end());
  for (const char letter : distinct) {
    const bool motors = k.corexy && (letter == 'X' || letter == 'Y');
    if (!motors && map.find(letter) == std::string::npos) {
      r.warning("KINS", "KINEMATICS",
                std::string("axis ") + letter + " in [TRAJ] COORDINATES is driven by no joint");
    }
  }
  return map;
}

}  // namespace cncd::config
