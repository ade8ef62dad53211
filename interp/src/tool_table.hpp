// A LinuxCNC tool table (.tbl): "T<n> P<pocket> X.. Y.. Z.. A.. B.. C.. U.. V.. W.. D<dia>
// I<front> J<back> Q<orient> ;comment". Offsets are in machine units.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "cncd/interp/tool_entry.hpp"

namespace cncd::interp {

class ToolTable {
 public:
  // Returns an error text ("FILE:LINE: ...") on a malformed table or a value that is not
  // storable; nothing is loaded then.
  std::optional<std::string> load(const std::filesystem::path& path);
  const ToolEntry* find(int number) const;
  // Where tool `number` sits in the table: its line among the tool lines as loaded, from 1 (the
  // first line with that number), a tool added later after them. This is the index rs274 names
  // a tool by (CHANGE_TOOL, SET_TOOL_TABLE_ENTRY); a tool the table lacks (none loaded, or
  // tool 0) keeps its number.
  int slot(int number) const;
  // Adds or replaces the entry; refuses (returns why, changes nothing) one that is not
  // storable (stored_values.hpp). Every entry comes in here or through load().
  std::optional<std::string> set(const ToolEntry& entry);
  void clear() {
    tools_.clear();
    slots_.clear();
    lines_ = 0;
  }
  const std::map<int, ToolEntry>& entries() const { return tools_; }

 private:
  std::map<int, ToolEntry> tools_;
  std::map<int, int> slots_;  // tool number -> slot
  int lines_ = 0;             // slots given out
};

}  // namespace cncd::interp
