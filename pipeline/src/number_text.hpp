// Numbers as cncd-check and the check's messages print them.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace cncd::pipeline {

// Four decimals; an absurd number (past 1e9) in %.10g rather than hundreds of digits.
inline std::string fixed4(double value) {
  char text[64];
  std::snprintf(text, sizeof text, std::abs(value) <= 1e9 ? "%.4f" : "%.10g", value);
  return text;
}

}  // namespace cncd::pipeline
