// What G5 and G5.2 remember between blocks.
#pragma once

#include <vector>

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

struct SplineState {
  // The P and Q of the last G5: a G5 without I and J starts along the direction the last one
  // ended in (rs274 keeps them across other moves, 0 before any G5).
  double last_p = 0;
  double last_q = 0;
  // G5.2 .. G5.3: the control points gathered so far, while `open`.
  bool open = false;
  double inverse_f = 0;  // under G93, the last F among its lines
  NurbsFeed nurbs;
};

}  // namespace cncd::interp
