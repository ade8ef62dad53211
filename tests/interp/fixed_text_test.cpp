// The fast "%.4f" formatter behind the canonical-command text must give printf's bytes for
// every double: rounding of exact ties, negative zero, subnormals, magnitudes past its fast
// path, inf and nan.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "cncd/interp/fixed_text.hpp"

namespace cncd::interp {
namespace {

std::string by_printf(double value) {
  char text[400];
  const int n = std::snprintf(text, sizeof text, "%.4f", value);
  return std::string(text, static_cast<std::size_t>(n));
}

std::string by_us(double value) {
  std::string out = "x";  // appends, never overwrites
  append_fixed4(out, value);
  return out.substr(1);
}

// Counts and reports (a few of) the values where the two differ.
int mismatches(double value, int& reported) {
  const std::string want = by_printf(value);
  const std::string got = by_us(value);
  if (want == got) return 0;
  if (reported++ < 10)
    ADD_FAILURE() << "value " << std::hexfloat << value << ": printf " << want << ", ours " << got;
  return 1;
}

// Both signs, and the neighbouring doubles on either side.
int mismatches_around(double value, int& reported) {
  int count = 0;
  for (const double v : {value, -value}) {
    count += mismatches(v, reported);
    count += mismatches(std::nextafter(v, HUGE_VAL), reported);
    count += mismatches(std::nextafter(v, -HUGE_VAL), reported);
  }
  return count;
}

TEST(FixedText, SpecialValues) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double v : {0.0, -0.0, inf, -inf, nan, -nan, DBL_MAX, -DBL_MAX, DBL_MIN, -DBL_MIN,
                         std::numeric_limits<double>::denorm_min(),
                         -std::numeric_limits<double>::denorm_min(), 1e-300, -1e-300}) {
    EXPECT_EQ(by_us(v), by_printf(v)) << v;
  }
  EXPECT_EQ(by_us(-0.0), "-0.0000");
  EXPECT_EQ(by_us(-0.00004), "-0.0000");
  EXPECT_EQ(by_us(0.00005), by_printf(0.00005));
  EXPECT_EQ(by_us(1.23445), by_printf(1.23445));
}

// At four decimals a double lies exactly halfway between two results only if it is an odd
// multiple of 1/32 (x * 10^4 = k + 1/2 with x dyadic); printf rounds those to even.
TEST(FixedText, ExactTiesRoundToEven) {
  EXPECT_EQ(by_us(0.03125), "0.0312");
  EXPECT_EQ(by_us(0.09375), "0.0938");
  EXPECT_EQ(by_us(-1.03125), "-1.0312");
  int reported = 0;
  int count = 0;
  for (std::int64_t k = 1; k < 200'000; k += 2)
    count += mismatches_around(static_cast<double>(k) / 32, reported);
  for (std::int64_t big = 1; big < (std::int64_t{1} << 47); big = big * 3 + 1)
    count += mismatches_around(static_cast<double>(big) + 1.0 / 32, reported);
  EXPECT_EQ(count, 0);
}

TEST(FixedText, DecimalsAndIntegers) {
  int reported = 0;
  int count = 0;
  for (int n = -200'000; n <= 200'000; ++n) {
    count += mismatches(n / 10000.0, reported);   // exactly representable or nearly
    count += mismatches(n / 100000.0, reported);  // the fifth decimal decides, 5 included
    count += mismatches(n / 1000.0 + 0.00005, reported);
    count += mismatches(static_cast<double>(n), reported);
  }
  EXPECT_EQ(count, 0);
}

TEST(FixedText, EveryMagnitude) {
  int reported = 0;
  int count = 0;
  std::mt19937_64 random(20240611);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  for (int exponent = -20; exponent <= 22; ++exponent) {
    const double scale = std::pow(10.0, exponent);
    count += mismatches_around(scale, reported);
    for (int i = 0; i < 5000; ++i)
      count += mismatches_around(mantissa(random) * scale, reported);
  }
  // Around the end of the fast path (1e14) and where whole numbers stop having a fraction.
  for (const double edge : {1e14, 9.999999999999e13, 4503599627370496.0, 9007199254740992.0, 1e15,
                            1e16, 1e17, 1e18, 1e19, 1e20, 18446744073709551616.0}) {
    double v = edge;
    for (int i = 0; i < 1000; ++i, v = std::nextafter(v, 0.0))
      count += mismatches_around(v, reported);
  }
  EXPECT_EQ(count, 0);
}

TEST(FixedText, RandomBitPatterns) {
  int reported = 0;
  int count = 0;
  std::mt19937_64 random(7);
  for (int i = 0; i < 100'000; ++i) {
    const std::uint64_t bits = random();
    double value = 0;
    std::memcpy(&value, &bits, sizeof value);
    count += mismatches(value, reported);
  }
  EXPECT_EQ(count, 0);
}

TEST(FixedText, Integers) {
  for (const long long v :
       {0LL, 1LL, -1LL, 42LL, -2147483648LL, 2147483647LL, std::numeric_limits<long long>::min()}) {
    std::string out = "x";
    append_int(out, v);
    EXPECT_EQ(out, "x" + std::to_string(v));
  }
}

}  // namespace
}  // namespace cncd::interp
