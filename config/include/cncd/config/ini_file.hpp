// Raw reader for LinuxCNC-style INI files, faithful to how LinuxCNC 2.9 reads them:
//  - `[SECTION]` starts a section; text after the closing `]` is ignored (LinuxCNC matches the
//    header as a prefix). Names are case-sensitive.
//  - `KEY = VALUE`; the value is everything after the first `=`, trimmed. Trailing `# ...` is
//    NOT stripped from the raw value (LinuxCNC keeps it); typed readers tolerate it after a number.
//  - Lines whose first non-blank character is `#` or `;` are comments.
//  - A line ending in `\` continues on the next line (the lines are joined as they are).
//  - `#INCLUDE file` inserts another file, relative to the including file's directory (`~` and
//    `$VAR` are expanded like the linuxcnc start script does). Unlike LinuxCNC, includes may
//    nest, up to kMaxIncludeDepth levels; loops are reported.
//  - Repeated keys are kept in order. A repeated section is kept too, but like LinuxCNC the
//    lookups below only see the first section of a name.
//  - `[SECTION]KEY` references are not substituted inside values (LinuxCNC 2.9 does not either);
//    find_reference() resolves one when a caller wants to.
// Reading never throws on bad input: every problem is reported with its file and line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cncd/config/machine_config.hpp"

namespace cncd::config {

inline constexpr int kMaxIncludeDepth = 16;
inline constexpr std::size_t kMaxLineLength = 4096;                  // bytes, after joining
inline constexpr std::uintmax_t kMaxFileSize = 16u * 1024u * 1024u;  // bytes

struct IniEntry {
  std::string section;  // without brackets; empty for keys before the first section
  std::string key;
  std::string value;       // verbatim, surrounding blanks removed
  SourceRef source;        // file and (first) line of the KEY = VALUE line
  int section_occurrence;  // 0 in the first [SECTION] of that name, 1 in the second ...
  bool used = false;       // set by load_machine_config for every key it interprets
};

struct IniSection {
  std::string name;
  SourceRef source;
  int occurrence = 0;
};

class IniFile {
 public:
  // Reads `path` and its includes. Problems make the file unusable as a machine config;
  // warnings are things LinuxCNC itself tolerates (a missing include, a stray line).
  static IniFile read(const std::filesystem::path& path, std::vector<Problem>& problems,
                      std::vector<Problem>& warnings);

  // The n-th (1-based) KEY in the first [SECTION] of that name, as LinuxCNC's Find() does.
  const IniEntry* find(std::string_view section, std::string_view key, int n = 1) const;
  // Every KEY in the first [SECTION], in file order.
  std::vector<const IniEntry*> find_all(std::string_view section, std::string_view key) const;
  std::optional<std::string> value(std::string_view section, std::string_view key) const;
  // Resolves a reference written as `[SECTION]KEY` (blanks around it allowed); nullptr when
  // the text is not a reference or the key does not exist.
  const IniEntry* find_reference(std::string_view reference) const;

  const IniSection* section(std::string_view name, int occurrence = 0) const;
  bool has_section(std::string_view name) const { return section(name) != nullptr; }

  const std::vector<IniEntry>& entries() const { return entries_; }
  const std::vector<IniSection>& sections() const { return sections_; }
  // Keys no reader marked as used, e.g. [HAL] HALFILE; worth listing at debug level.
  std::vector<const IniEntry*> unused_entries() const;

  // Marks an entry (by its address in entries()) as interpreted.
  void mark_used(const IniEntry& entry);

  const std::filesystem::path& path() const { return path_; }
  // Directory that relative paths in values are resolved against.
  std::filesystem::path directory() const;

 private:
  friend class IniParser;
  std::filesystem::path path_;
  std::vector<IniEntry> entries_;
  std::vector<IniSection> sections_;
};

}  // namespace cncd::config
