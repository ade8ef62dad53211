// The holes a program drills, found in the moves the pipeline makes of its canonical commands
// (machine coordinates and units), whatever wrote them: a canned cycle of either dialect, a
// G1 plunge, an O-word loop. A hole is a run of straight feeds down along Z at one XY; the
// moves up and down at that XY that follow (the pecks of G73/G83, the retract, a second
// plunge) belong to it until the tool moves off that XY or another axis than Z moves.
// One thread at a time.
#pragma once

#include <vector>

#include "cncd/interp/canon.hpp"

namespace cncd::pipeline {

struct Hole {
  int line = 0;  // program line of the first feed down
  double x = 0;  // machine coordinates and units
  double y = 0;
  double top = 0;     // Z where the first feed down starts
  double bottom = 0;  // the lowest Z reached at this XY while the hole lasts
};

class HoleFinder {
 public:
  // A straight move (traverse or feed) from `from` to `to`, in program order.
  void straight(const interp::Pose& from, const interp::Pose& to, bool feed, int line);
  // A move that is not straight (an arc) ends the hole under way.
  void other_motion() { open_ = false; }

  const std::vector<Hole>& holes() const { return holes_; }

 private:
  std::vector<Hole> holes_;
  bool open_ = false;  // the last of holes_ is still being drilled
};

}  // namespace cncd::pipeline
