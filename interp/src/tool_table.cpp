#include "tool_table.hpp"

#include <cctype>
#include <charconv>
#include <fstream>

#include "cncd/interp/stored_values.hpp"
#include "failure.hpp"

namespace cncd::interp {

std::optional<std::string> ToolTable::load(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return "Unable to open tool table: " + path.string();
  std::map<int, ToolEntry> loaded;
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    ToolEntry entry;
    const auto semicolon = text.find(';');
    if (semicolon != std::string::npos) {
      const auto first = text.find_first_not_of(" \t", semicolon + 1);
      const auto last = text.find_last_not_of(" \t\r");
      if (first != std::string::npos && last >= first)
        entry.comment = text.substr(first, last - first + 1);
      text.resize(semicolon);
    }
    bool has_tool = false;
    std::size_t i = 0;
    while (i < text.size()) {
      const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[i])));
      if (std::isspace(static_cast<unsigned char>(text[i]))) {
        ++i;
        continue;
      }
      std::size_t end = i + 1;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])))
        ++end;
      double value = 0;
      const char* first = text.data() + i + 1;
      if (first < text.data() + end && *first == '+') ++first;
      const auto result = std::from_chars(first, text.data() + end, value);
      if (result.ec != std::errc() || result.ptr != text.data() + end) {
        return path.string() + ":" + std::to_string(line_number) + ": bad value '" +
               text.substr(i, end - i) + "'";
      }
      const char* axes = "XYZABCUVW";
      for (int axis = 0; axis < kAxes; ++axis) {
        if (letter == axes[axis]) entry.offset[static_cast<std::size_t>(axis)] = value;
      }
      switch (letter) {
        case 'T':
          entry.number = to_int(value);
          has_tool = true;
          break;
        case 'P':
          entry.pocket = to_int(value);
          break;
        case 'D':
          entry.diameter = value;
          break;
        case 'I':
          entry.front_angle = value;
          break;
        case 'J':
          entry.back_angle = value;
          break;
        case 'Q':
          entry.orientation = to_int(value);
          break;
        default:
          break;
      }
      i = end;
    }
    if (!has_tool) continue;
    if (auto problem = tool_entry_problem(entry)) {
      return path.string() + ":" + std::to_string(line_number) + ": " + *problem;
    }
    loaded[entry.number] = entry;
  }
  tools_ = std::move(loaded);
  return std::nullopt;
}

std::optional<std::string> ToolTable::set(const ToolEntry& entry) {
  if (auto problem = tool_entry_problem(entry)) return problem;
  tools_[entry.number] = entry;
  return std::nullopt;
}

const ToolEntry* ToolTable::find(int number) const {
  const auto it = tools_.find(number);
  return it == tools_.end() ? nullptr : &it->second;
}

}  // namespace cncd::interp
