// Which dialect a program is read in: its first line "(dialect NAME)", else the options'.
#include <cctype>
#include <optional>
#include <string>

#include "failure.hpp"
#include "interp_state.hpp"
#include "source.hpp"

namespace cncd::interp {
namespace {

// "(dialect NAME)" as the whole line: NAME with its blanks trimmed; otherwise nothing.
std::optional<std::string> dialect_comment(const std::string& text) {
  std::string lower;
  for (const char c : text)
    lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  while (!lower.empty() && (lower.back() == ' ' || lower.back() == '\t' || lower.back() == '\r'))
    lower.pop_back();
  if (lower.size() < 2 || lower.front() != '(' || lower.find(')') != lower.size() - 1)
    return std::nullopt;
  const std::string inner = lower.substr(1, lower.size() - 2);
  const std::size_t word = inner.find_first_not_of(" \t");
  if (word == std::string::npos || inner.compare(word, 7, "dialect") != 0) return std::nullopt;
  if (inner.size() > word + 7 && inner[word + 7] != ' ' && inner[word + 7] != '\t')
    return std::nullopt;
  std::string name = inner.substr(word + 7);
  const std::size_t from = name.find_first_not_of(" \t");
  const std::size_t to = name.find_last_not_of(" \t");
  return from == std::string::npos ? std::string() : name.substr(from, to - from + 1);
}

}  // namespace

const char* dialect_name(Dialect dialect) {
  return dialect == Dialect::numeryx ? "numeryx" : "linuxcnc";
}

std::optional<Dialect> parse_dialect(std::string_view name) {
  while (!name.empty() && (name.front() == ' ' || name.front() == '\t'))
    name.remove_prefix(1);
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t'))
    name.remove_suffix(1);
  std::string lower;
  for (const char c : name)
    lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (lower == "linuxcnc") return Dialect::linuxcnc;
  if (lower == "numeryx") return Dialect::numeryx;
  return std::nullopt;
}

void Interpreter::Impl::detect_dialect() {
  dialect_ = options_.dialect;
  if (options_.dialect_from_first_line) {
    LineSource& source = sources_.back();
    std::string line;
    while (source.read_line(line)) {
      const std::size_t first = line.find_first_not_of(" \t");
      if (first == std::string::npos || is_percent_line(line)) continue;
      if (const auto named = dialect_comment(line.substr(first))) {
        const auto dialect = parse_dialect(*named);
        if (!dialect) {
          current_line_ = source.line_number();
          fail("Unknown dialect '" + *named + "' (linuxcnc or numeryx)");
        }
        dialect_ = *dialect;
      }
      break;
    }
    source.seek(0, 0);
    current_line_ = 0;
  }
  // Numeryx cycles start with G98 (retract to the initial Z); LinuxCNC starts with G99.
  if (dialect_ == Dialect::numeryx) modal_.retract_r_plane = false;
}

}  // namespace cncd::interp
