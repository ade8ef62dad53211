#include "cncd/config/ini_file.hpp"

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <map>
#include <system_error>

#include "text.hpp"

namespace cncd::config {
namespace {

// A file full of binary junk would otherwise produce one problem a line.
constexpr int kMaxBadLinesPerFile = 10;

std::optional<std::string> read_whole_file(const std::filesystem::path& path, std::string& error) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error = "is a directory, not an INI file";
    return std::nullopt;
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxFileSize) {
    error = "file is too large (" + std::to_string(size) + " bytes, limit " +
            std::to_string(kMaxFileSize) + ")";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open file: " + std::error_code(errno, std::generic_category()).message();
    return std::nullopt;
  }
  std::string text;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxFileSize) {
      error = "file is too large (limit " + std::to_string(kMaxFileSize) + " bytes)";
      return std::nullopt;
    }
  }
  if (in.bad()) {
    error = "read error";
    return std::nullopt;
  }
  return text;
}

// `~` and `$NAME` / `${NAME}` expansion and quote removal, as the linuxcnc script's
// `eval echo` does for #INCLUDE names.
std::string expand_include_name(std::string_view name) {
  if (name.size() >= 2 && (name.front() == '"' || name.front() == '\'') &&
      name.back() == name.front()) {
    name = name.substr(1, name.size() - 2);
  }
  std::string out;
  std::size_t i = 0;
  if (name.starts_with("~/") || name == "~") {
    const char* home = std::getenv("HOME");
    out = home != nullptr ? home : "";
    i = 1;
  }
  while (i < name.size()) {
    if (name[i] != '$' || i + 1 >= name.size()) {
      out += name[i++];
      continue;
    }
    std::size_t start = i + 1;
    std::size_t end = start;
    const bool braced = name[start] == '{';
    if (braced) {
      end = name.find('}', start);
      if (end == std::string_view::npos) {
        out += name.substr(i);
        break;
      }
      ++start;
    } else {
      while (end < name.size() &&
             (std::isalnum(static_cast<unsigned char>(name[end])) != 0 || name[end] == '_')) {
        ++end;
      }
    }
    const std::string var(name.substr(start, end - start));
    const char* value = var.empty() ? nullptr : std::getenv(var.c_str());
    if (var.empty()) out += '$';
    if (value != nullptr) out += value;
    i = braced ? end + 1 : end;
  }
  return out;
}

}  // namespace

class IniParser {
 public:
  IniParser(IniFile& ini, std::vector<Problem>& problems, std::vector<Problem>& warnings)
      : ini_(ini), problems_(problems), warnings_(warnings) {}

  void parse_file(const std::filesystem::path& path, const SourceRef* included_from) {
    const std::filesystem::path normal = path.lexically_normal();
    const std::string file = normal.string();
    std::error_code ec;
    auto canonical = std::filesystem::weakly_canonical(normal, ec);
    if (ec) canonical = normal;
    for (const auto& open : include_stack_) {
      if (open == canonical) {
        add(problems_, *included_from, "", "#INCLUDE",
            "include loop: " + file + " is already being read");
        return;
      }
    }
    if (include_stack_.size() > static_cast<std::size_t>(kMaxIncludeDepth)) {
      add(problems_, *included_from, "", "#INCLUDE",
          "includes nested deeper than " + std::to_string(kMaxIncludeDepth) + " levels");
      return;
    }
    std::string error;
    const auto text = read_whole_file(normal, error);
    if (!text) {
      // LinuxCNC reports an unreadable include and starts anyway; the main file must exist.
      if (included_from != nullptr) {
        add(warnings_, *included_from, "", "#INCLUDE", "cannot read " + file + ": " + error);
      } else {
        add(problems_, SourceRef{file, 0}, "", "", error);
      }
      return;
    }
    include_stack_.push_back(canonical);
    parse_text(*text, file, normal.parent_path());
    include_stack_.pop_back();
  }

 private:
  void parse_text(std::string_view text, const std::string& file,
                  const std::filesystem::path& dir) {
    int bad_lines = 0;
    int line_no = 0;
    std::size_t pos = 0;
    while (pos < text.size() && bad_lines <= kMaxBadLinesPerFile) {
      const int first_line = line_no + 1;
      std::string logical;
      bool too_long = false;
      // Join physical lines ending in a backslash, as LinuxCNC does.
      while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view physical = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_no;
        if (!physical.empty() && physical.back() == '\r') physical.remove_suffix(1);
        const bool continued = !physical.empty() && physical.back() == '\\';
        if (continued) physical.remove_suffix(1);
        if (logical.size() + physical.size() > kMaxLineLength) {
          too_long = true;
        } else if (!too_long) {
          logical.append(physical);
        }
        if (!continued) break;
      }
      const SourceRef where{file, first_line};
      if (too_long) {
        add(problems_, where, "", "",
            "line longer than " + std::to_string(kMaxLineLength) + " bytes; ignored");
        ++bad_lines;
        continue;
      }
      if (const auto bad = find_control_char(logical)) {
        add(problems_, where, "", "",
            *bad == 0
                ? std::string("line contains a NUL byte; is this a text file?")
                : "line contains control character " + hex_byte(*bad) + "; is this a text file?");
        ++bad_lines;
        continue;
      }
      parse_line(logical, where, dir);
    }
    if (bad_lines > kMaxBadLinesPerFile) {
      add(problems_, SourceRef{file, line_no}, "", "",
          "too many unreadable lines; stopped reading this file");
    }
  }

  void parse_line(std::string_view line, const SourceRef& where, const std::filesystem::path& dir) {
    const std::string_view body = trim(line);
    if (body.empty()) return;
    if (body.starts_with("#INCLUDE") && (body.size() == 8 || body[8] == ' ' || body[8] == '\t')) {
      include(trim(body.substr(8)), where, dir);
      return;
    }
    if (body.front() == '#' || body.front() == ';') return;
    if (body.front() == '[') {
      start_section(body, where);
      return;
    }
    const std::size_t equal = body.find('=');
    if (equal == std::string_view::npos) {
      add(warnings_, where, current_.value_or(""), "",
          "ignored: not a [SECTION], comment or KEY = VALUE line: '" + printable(body) + "'");
      return;
    }
    const std::string key(trim(body.substr(0, equal)));
    if (key.empty()) {
      add(warnings_, where, current_.value_or(""), "", "ignored: no key before '='");
      return;
    }
    if (!current_) {
      if (!broken_section_) add(warnings_, where, "", key, "key outside any [SECTION]; ignored");
      return;
    }
    if (key.find_first_of(" \t") != std::string::npos) {
      add(warnings_, where, *current_, key, "key contains blanks; LinuxCNC will not find it");
    }
    ini_.entries_.push_back(IniEntry{*current_, key, std::string(trim(body.substr(equal + 1))),
                                     where, occurrence_, false});
  }

  void start_section(std::string_view body, const SourceRef& where) {
    current_.reset();
    broken_section_ = true;
    const std::size_t close = body.find(']');
    if (close == std::string_view::npos) {
      add(problems_, where, "", "",
          "unterminated section header '" + printable(body) + "' (missing ']')");
      return;
    }
    const std::string name(body.substr(1, close - 1));
    if (trim(name).empty()) {
      add(problems_, where, "", "", "section header '[]' has no name");
      return;
    }
    const std::string_view rest = trim(body.substr(close + 1));
    if (!rest.empty() && rest.front() != '#' && rest.front() != ';') {
      add(warnings_, where, name, "", "text after ']' ignored: '" + printable(rest) + "'");
    }
    occurrence_ = section_counts_[name]++;
    ini_.sections_.push_back(IniSection{name, where, occurrence_});
    current_ = name;
    broken_section_ = false;
  }

  void include(std::string_view name, const SourceRef& where, const std::filesystem::path& dir) {
    if (name.empty()) {
      add(warnings_, where, "", "#INCLUDE", "#INCLUDE without a file name; ignored");
      return;
    }
    std::filesystem::path target = expand_include_name(name);
    if (target.is_relative()) target = dir / target;
    parse_file(target, &where);
  }

  static void add(std::vector<Problem>& into, const SourceRef& where, std::string section,
                  std::string key, std::string message) {
    into.push_back(
        Problem{where.file, where.line, std::move(section), std::move(key), std::move(message)});
  }

  IniFile& ini_;
  std::vector<Problem>& problems_;
  std::vector<Problem>& warnings_;
  std::vector<std::filesystem::path> include_stack_;
  std::map<std::string, int, std::less<>> section_counts_;
  std::optional<std::string> current_;
  bool broken_section_ = false;  // keys after a bad header were covered by its problem
  int occurrence_ = 0;
};

IniFile IniFile::read(const std::filesystem::path& path, std::vector<Problem>& problems,
                      std::vector<Problem>& warnings) {
  IniFile ini;
  ini.path_ = path;
  IniParser parser(ini, problems, warnings);
  parser.parse_file(path, nullptr);
  return ini;
}

const IniEntry* IniFile::find(std::string_view section, std::string_view key, int n) const {
  for (const auto& entry : entries_) {
    if (entry.section_occurrence == 0 && entry.section == section && entry.key == key && --n <= 0) {
      return &entry;
    }
  }
  return nullptr;
}

std::vector<const IniEntry*> IniFile::find_all(std::string_view section,
                                               std::string_view key) const {
  std::vector<const IniEntry*> found;
  for (const auto& entry : entries_) {
    if (entry.section_occurrence == 0 && entry.section == section && entry.key == key) {
      found.push_back(&entry);
    }
  }
  return found;
}

std::optional<std::string> IniFile::value(std::string_view section, std::string_view key) const {
  const IniEntry* entry = find(section, key);
  if (entry == nullptr) return std::nullopt;
  return entry->value;
}

const IniEntry* IniFile::find_reference(std::string_view reference) const {
  reference = trim(reference);
  if (!reference.starts_with('[')) return nullptr;
  const std::size_t close = reference.find(']');
  if (close == std::string_view::npos || close + 1 >= reference.size()) return nullptr;
  return find(reference.substr(1, close - 1), reference.substr(close + 1));
}

const IniSection* IniFile::section(std::string_view name, int occurrence) const {
  for (const auto& s : sections_) {
    if (s.name == name && s.occurrence == occurrence) return &s;
  }
  return nullptr;
}

std::vector<const IniEntry*> IniFile::unused_entries() const {
  std::vector<const IniEntry*> unused;
  for (const auto& entry : entries_) {
    if (!entry.used) unused.push_back(&entry);
  }
  return unused;
}

void IniFile::mark_used(const IniEntry& entry) {
  for (auto& candidate : entries_) {
    if (&candidate == &entry) {
      candidate.used = true;
      return;
    }
  }
}

std::filesystem::path IniFile::directory() const {
  const auto parent = path_.parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

}  // namespace cncd::config
