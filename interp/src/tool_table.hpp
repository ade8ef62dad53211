// A LinuxCNC tool table (.tbl): "T<n> P<pocket> X.. Y.. Z.. A.. B.. C.. U.. V.. W.. D<dia>
// I<front> J<back> Q<orient> ;comment". Offsets are in machine units.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

struct ToolEntry {
  int number = 0;
  int pocket = 0;
  Pose offset{};
  double diameter = 0;
  double front_angle = 0;
  double back_angle = 0;
  int orientation = 0;
};

class ToolTable {
 public:
  // Returns an error text ("FILE:LINE: ...") on a malformed table.
  std::optional<std::string> load(const std::filesystem::path& path);
  const ToolEntry* find(int number) const;
  void set(const ToolEntry& entry) { tools_[entry.number] = entry; }

 private:
  std::map<int, ToolEntry> tools_;
};

}  // namespace cncd::interp
