#include "tool_table.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <fstream>

#include "cncd/interp/stored_values.hpp"
#include "failure.hpp"

namespace cncd::interp {
namespace {
constexpr const char* kWordLetters = "TPXYZABCUVWDIJQ";
constexpr const char* kWordList = "T P X Y Z A B C U V W D I J Q";
}  // namespace

std::optional<std::string> ToolTable::load(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return "Unable to open tool table: " + path.string();
  std::map<int, ToolEntry> loaded;
  std::map<int, int> slots;
  int lines = 0;  // a tool line takes the next slot even when its number came before
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
    bool has_word = false;
    std::size_t i = 0;
    const std::string where = path.string() + ":" + std::to_string(line_number) + ": ";
    while (i < text.size()) {
      const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[i])));
      if (std::isspace(static_cast<unsigned char>(text[i]))) {
        ++i;
        continue;
      }
      std::size_t end = i + 1;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])))
        ++end;
      // Recognised before it is trusted: a file of something else (a parameter file, the old
      // table of bare numbers) would otherwise load as an empty table.
      if (std::strchr(kWordLetters, letter) == nullptr || letter == '\0') {
        std::string word = text.substr(i, std::min<std::size_t>(end - i, 40));
        for (char& c : word)
          c = std::isprint(static_cast<unsigned char>(c)) ? c : '?';
        return where + "'" + word + "' is not a tool table word (" + kWordList + ")" +
               (loaded.empty() ? ": is this a tool table?" : "");
      }
      has_word = true;
      double value = 0;
      const char* first = text.data() + i + 1;
      if (first < text.data() + end && *first == '+') ++first;
      const auto result = std::from_chars(first, text.data() + end, value);
      if (result.ec != std::errc() || result.ptr != text.data() + end) {
        return where + "bad value '" + text.substr(i, end - i) + "'";
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
    if (!has_word) continue;
    if (!has_tool) return where + "no T word: a tool line is 'T<number> P<pocket> ... ;comment'";
    if (auto problem = tool_entry_problem(entry)) return where + *problem;
    loaded[entry.number] = entry;
    slots.emplace(entry.number, ++lines);
  }
  tools_ = std::move(loaded);
  lines_ = lines;
  slots_ = std::move(slots);
  return std::nullopt;
}

std::optional<std::string> ToolTable::set(const ToolEntry& entry) {
  if (auto problem = tool_entry_problem(entry)) return problem;
  tools_[entry.number] = entry;
  if (slots_.emplace(entry.number, lines_ + 1).second) ++lines_;
  return std::nullopt;
}

int ToolTable::slot(int number) const {
  const auto it = slots_.find(number);
  return it == slots_.end() ? number : it->second;
}

const ToolEntry* ToolTable::find(int number) const {
  const auto it = tools_.find(number);
  return it == tools_.end() ? nullptr : &it->second;
}

}  // namespace cncd::interp
