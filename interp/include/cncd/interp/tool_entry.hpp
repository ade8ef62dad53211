// One tool of a LinuxCNC tool table (.tbl): "T<n> P<pocket> X.. Y.. Z.. A.. B.. C.. U.. V.. W..
// D<dia> I<front> J<back> Q<orient> ;comment". Offsets and diameter in the tool table's units.
#pragma once

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
  std::string comment;  // the text after ';', without leading blanks

  bool operator==(const ToolEntry&) const = default;
};

}  // namespace cncd::interp
