// Fixed-point text of doubles, byte for byte what printf's "%.4f" gives (round to nearest, ties
// to even, "-0.0000" for negative values that round to zero), without printf's cost: the
// canonical-command text of a long program is mostly such numbers.
#pragma once

#include <string>

namespace cncd::interp {

// Appends printf("%.4f", value) to `out`.
void append_fixed4(std::string& out, double value);

// Appends printf("%d", value) to `out`.
void append_int(std::string& out, long long value);

}  // namespace cncd::interp
