// Tool centre point control in the feeder (docs/kinematics.md): M428 and M429, switched with
// the rotaries anywhere, and the tool length offset under TCP, which the kinematics turn the tip
// with (Move::tool_length) and which may change only where that moves no joint.
#include <cmath>
#include <string>

#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/feeder.hpp"
#include "number_text.hpp"

namespace cncd::pipeline {
namespace {

// A joint that moves less than this (machine units or degrees) stands still.
constexpr double kSameJoint = 1e-6;

}  // namespace

void ProgramFeeder::switch_tcp(bool on, int line) {
  if (unsupported_) return;
  const std::string code = on ? "M428" : "M429";
  if (kins_ && !kins_->has_tcp()) {
    unsupported_ = Unsupported{line, code + " switches tool centre point control, which needs " +
                                         "xyzac-trt-kins or xyzbc-trt-kins; [KINS] KINEMATICS " +
                                         "is " + machine_->kinematics};
    return;
  }
  if (on == tcp_) return;
  if (on && !tcp_tool_offset_fits(line, code)) return;
  // The tool stays where it is; the program goes on in the other frame (the interpreter has
  // made the same change to its position, through tcp_switched()).
  end_ = tcp_switched(end_, on);
  tcp_ = on;
}

motion::AxisPose ProgramFeeder::tcp_switched(const motion::AxisPose& machine, bool on) const {
  return on == tcp_ ? machine : in_frame(machine, on);
}

motion::AxisPose ProgramFeeder::in_frame(const motion::AxisPose& machine, bool on) const {
  if (!kins_ || !kins_->has_tcp()) return machine;
  motion::AxisPose moved = machine;
  if (on) {
    kins_->tcp_forward(machine, tool_length_, moved);
  } else {
    kins_->tcp_inverse(machine, tool_length_, moved);
  }
  return moved;
}

bool ProgramFeeder::tcp_tool_offset_fits(int line, const std::string& what) {
  // The kinematics turn the tip about the tool's length along Z alone (LinuxCNC's take
  // motion.tooloffset.z): a tool offset in X or Y would leave the tip off the point they hold.
  const interp::Pose& offset = tracker_.tool_offset();
  if (offset[0] == 0 && offset[1] == 0) return true;
  unsupported_ = Unsupported{line, what + " with a tool offset of X" + fixed4(offset[0]) + " Y" +
                                       fixed4(offset[1]) +
                                       ": under TCP (M428) the tool is turned about its length "
                                       "along Z only; give the tool no X or Y offset"};
  return false;
}

void ProgramFeeder::change_tool_length(int line) {
  const double before = tool_length_;
  tool_length_ = tracker_.tool_offset()[2];
  if (unsupported_ || !tcp_) return;
  if (!tcp_tool_offset_fits(line, "a tool length offset (G43, G43.1, G43.2)")) return;
  if (tool_length_ == before || !kins_) return;
  // LinuxCNC applies a new tool length at rest, and its kinematics then put the joints where
  // the new tool's tip is on the part's point: with the table tilted that is elsewhere, a
  // jump no program line asked for. At the tilting axis's 0 every joint stays where it is.
  motion::AxisPose was{};
  motion::AxisPose now{};
  kins_->tcp_inverse(end_, before, was);
  kins_->tcp_inverse(end_, tool_length_, now);
  bool jumps = false;
  for (std::size_t i = 0; i < was.size(); ++i)
    jumps = jumps || std::abs(now[i] - was[i]) > kSameJoint;
  if (!jumps) return;
  const std::size_t tilt = std::abs(end_[3]) > std::abs(end_[4]) ? 3 : 4;
  const std::string letter(1, config::kAxisLetters[tilt]);
  unsupported_ = Unsupported{
      line, "the tool length offset changes from Z" + fixed4(before) + " to Z" +
                fixed4(tool_length_) + " under TCP (M428) with " + letter + " at " +
                fixed4(end_[tilt]) +
                ": the joints would jump to put the new tool's tip on the part; change the tool "
                "length (G43, G43.1, G43.2, G49) with " +
                letter + " at 0"};
}

}  // namespace cncd::pipeline
