#include "cncd/interp/fixed_text.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace cncd::interp {
namespace {

// Values at or above this magnitude (and inf, nan) go to printf itself: they never come from a
// real program, and below it the result of the integer arithmetic fits in 63 bits.
constexpr double kFastLimit = 1e14;

}  // namespace

void append_fixed4(std::string& out, double value) {
  if (!(std::fabs(value) < kFastLimit)) {
    char text[400];  // "%.4f" of DBL_MAX is 316 characters
    const int n = std::snprintf(text, sizeof text, "%.4f", value);
    if (n > 0) out.append(text, static_cast<std::size_t>(n));
    return;
  }
  // value = mantissa * 2^exponent exactly, so value * 10^4 = mantissa * 5^4 * 2^(exponent + 4)
  // where mantissa * 5^4 < 2^53 * 2^10 fits in 64 bits; below kFastLimit the exponent + 4 is
  // at most -2, so the rounding below is a shift right with an exact remainder.
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  const bool negative = (bits >> 63) != 0;
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (biased != 0) mantissa |= std::uint64_t{1} << 52;  // normal; else subnormal
  const int shift = 1075 - (biased == 0 ? 1 : biased) - 4;
  const std::uint64_t scaled = mantissa * 625;
  std::uint64_t units = 0;  // round(|value| * 10^4), ties to even as printf
  if (shift < 64) {
    units = scaled >> shift;
    const std::uint64_t rest = scaled & ((std::uint64_t{1} << shift) - 1);
    const std::uint64_t half = std::uint64_t{1} << (shift - 1);
    if (rest > half || (rest == half && (units & 1) != 0)) ++units;
  }  // else scaled < 2^63 <= half: rounds to zero

  char text[32];
  char* p = text;
  if (negative) *p++ = '-';
  p = std::to_chars(p, text + sizeof text, units / 10000).ptr;
  const auto fraction = static_cast<unsigned>(units % 10000);
  p[0] = '.';
  p[1] = static_cast<char>('0' + fraction / 1000);
  p[2] = static_cast<char>('0' + fraction / 100 % 10);
  p[3] = static_cast<char>('0' + fraction / 10 % 10);
  p[4] = static_cast<char>('0' + fraction % 10);
  out.append(text, static_cast<std::size_t>(p + 5 - text));
}

void append_int(std::string& out, long long value) {
  char text[24];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  out.append(text, static_cast<std::size_t>(end - text));
}

}  // namespace cncd::interp
