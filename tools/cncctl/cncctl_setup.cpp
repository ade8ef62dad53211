// cncctl tools and offsets: the tool table and the coordinate system origins.
#include <cctype>
#include <cstdio>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {
bool is_axis_letter(char c) {
  return std::string_view("XYZABCUVW").find(c) != std::string_view::npos;
}

// "Z12.5" -> ('Z', 12.5); throws UsageError.
std::pair<char, double> word(const std::string& token, const char* command) {
  if (token.size() < 2 || !std::isalpha(static_cast<unsigned char>(token[0]))) {
    throw UsageError{std::string(command) + ": '" + token + "' is not a word like Z12.5"};
  }
  const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(token[0])));
  return {letter, number_arg(token.substr(1), std::string(1, letter) + " word")};
}

int whole(double value, char letter) {
  if (value != static_cast<double>(static_cast<int>(value))) {
    throw UsageError{std::string(1, letter) + " needs a whole number"};
  }
  return static_cast<int>(value);
}

void print_tools(const json& list) {
  std::printf("%-6s %-6s %-36s %-10s %s\n", "tool", "pocket", "offset", "diameter", "comment");
  for (const auto& t : list["tools"]) {
    std::printf("T%-5d P%-5d %-36s %-10.4f %s\n", t.value("number", 0), t.value("pocket", 0),
                axes_text(t["offset"]).c_str(), t.value("diameter", 0.0),
                text_field(t, "comment").c_str());
  }
  std::printf("(%s, %s)\n", text_field(list, "path").c_str(), text_field(list, "units").c_str());
}

void print_offsets(const json& offsets) {
  const std::string active = text_field(offsets, "active");
  for (const auto& system : offsets["systems"]) {
    const std::string name = text_field(system, "name");
    std::printf("%-6s%s %s", name.c_str(), name == active ? "*" : " ",
                axes_text(system["origin"]).c_str());
    if (system.value("rotation", 0.0) != 0.0)
      std::printf("  R %.4f", system["rotation"].get<double>());
    std::printf("\n");
  }
  std::printf("%-7s %s\n", "G92", axes_text(offsets["g92"]).c_str());
  std::printf("(* active; %s, machine coordinates)\n", text_field(offsets, "units").c_str());
}
}  // namespace

int tools(daemon::Client& client, const Args& args, bool json_output) {
  if (args.size() == 1) return show(client, "tool.list", json_output, print_tools);
  if (args[1] != "set" || args.size() < 3) {
    throw UsageError{"tools takes no arguments, or: tools set T<n> [P..] [X..] [D..] [;comment]"};
  }
  json params = json::object();
  json offset = json::object();
  for (std::size_t i = 2; i < args.size(); ++i) {
    if (!args[i].empty() && args[i][0] == ';') {
      std::string comment = args[i].substr(1);
      for (std::size_t k = i + 1; k < args.size(); ++k)
        comment += " " + args[k];
      params["comment"] = comment;
      break;
    }
    const auto [letter, value] = word(args[i], "tools set");
    if (letter == 'T') {
      params["number"] = whole(value, letter);
    } else if (letter == 'P') {
      params["pocket"] = whole(value, letter);
    } else if (letter == 'Q') {
      params["orientation"] = whole(value, letter);
    } else if (letter == 'D') {
      params["diameter"] = value;
    } else if (letter == 'I') {
      params["front_angle"] = value;
    } else if (letter == 'J') {
      params["back_angle"] = value;
    } else if (is_axis_letter(letter)) {
      offset[std::string(1, static_cast<char>(std::tolower(letter)))] = value;
    } else {
      throw UsageError{std::string("tools set: unknown word '") + args[i] + "'"};
    }
  }
  if (!params.contains("number")) throw UsageError{"tools set needs the tool number: T<n>"};
  if (!offset.empty()) params["offset"] = offset;
  const json result = result_of(client.call("tool.set", params));
  if (json_output) {
    std::printf("%s\n", result.dump().c_str());
  } else {
    std::printf("T%d set\n", params["number"].get<int>());
  }
  return kDone;
}

int offsets(daemon::Client& client, const Args& args, bool json_output) {
  if (args.size() == 1) return show(client, "offsets.get", json_output, print_offsets);
  if (args[1] != "set" || args.size() < 4) {
    throw UsageError{"offsets takes no arguments, or: offsets set G54..G59.3 [X..] [R..]"};
  }
  json params = {{"system", args[2]}};
  json origin = json::object();
  for (std::size_t i = 3; i < args.size(); ++i) {
    const auto [letter, value] = word(args[i], "offsets set");
    if (letter == 'R') {
      params["rotation"] = value;
    } else if (is_axis_letter(letter)) {
      origin[std::string(1, static_cast<char>(std::tolower(letter)))] = value;
    } else {
      throw UsageError{std::string("offsets set: unknown word '") + args[i] + "'"};
    }
  }
  if (!origin.empty()) params["origin"] = origin;
  const json result = result_of(client.call("offsets.set", params));
  if (json_output) {
    std::printf("%s\n", result.dump().c_str());
  } else {
    std::printf("%s set\n", text_field(result, "system").c_str());
  }
  return kDone;
}

}  // namespace cncd::cncctl
