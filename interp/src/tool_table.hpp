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
  // Returns an error text ("FILE:LINE: ...") on a malformed table.
  std::optional<std::string> load(const std::filesystem::path& path);
  const ToolEntry* find(int number) const;
  void set(const ToolEntry& entry) { tools_[entry.number] = entry; }
  const std::map<int, ToolEntry>& entries() const { return tools_; }

 private:
  std::map<int, ToolEntry> tools_;
};

}  // namespace cncd::interp
