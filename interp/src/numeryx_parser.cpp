// The Numeryx dialect's syntax (application note An-101): a bare g (g0), the drilling cycle
// word and the R, Z, Q, D written after it, g10 polar positioning, address values given as
// expressions after '=', empty address words, for/next loops and gil().
#include <cmath>
#include <string>
#include <string_view>

#include "failure.hpp"
#include "parser.hpp"

namespace cncd::interp {
namespace {

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

bool is_cycle_word(int code) {
  return code == 730 || code == 740 || (code >= 810 && code <= 860);
}

}  // namespace

bool BlockParser::match_text(std::string_view word) {
  if (std::string_view(text_).substr(pos_, word.size()) != word) return false;
  pos_ += word.size();
  return true;
}

// A value is written after an address letter; otherwise the word is empty and reads as 0
// ("g" is g0, "r" the R plane at Z0, "i j" a pole at the origin).
bool BlockParser::nx_value_follows() const {
  const char c = peek();
  return is_digit(c) || c == '.' || c == '-' || c == '+' || c == '#' || c == '[' || c == '=';
}

double BlockParser::read_nx_value() {
  if (peek() == '=') {
    ++pos_;
    return read_nx_expression();
  }
  if (!nx_value_follows()) return 0.0;
  return read_real_value();
}

double BlockParser::read_nx_operand() {
  if (++depth_ > kMaxNesting) {
    error("Expression nested too deeply (more than " + std::to_string(kMaxNesting) + " levels)");
  }
  double value = 0;
  const char c = peek();
  const int col = column();
  if (c == '-' || c == '+') {
    ++pos_;
    value = read_nx_operand();
    if (c == '-') value = -value;
  } else if (c == '(') {
    ++pos_;
    value = read_nx_expression();
    if (peek() != ')') error("Right bracket missing");
    ++pos_;
  } else if (std::string_view(text_).substr(pos_, 4) == "gil(") {
    value = read_gil(col);
  } else if (c == '\0') {
    error("Value missing after '='");
  } else {
    value = read_real_value();
  }
  --depth_;
  return value;
}

// gil(x0, xn): the value proportional to the innermost for loop's variable over 0 .. its end
// value, x0 + (xn - x0) x #n / end: a loop 0 to 4 over 50 .. 150 gives 50, 75, 100, 125, 150.
double BlockParser::read_gil(int col) {
  pos_ += 4;  // "gil("
  const double first = read_nx_expression();
  if (peek() != ',') error("Comma missing between the two values of gil(x0,xn)");
  ++pos_;
  const double last = read_nx_expression();
  if (peek() != ')') error("Right bracket missing after gil(x0,xn)");
  ++pos_;
  if (gil_var_ == 0) fail("gil() used outside a for loop", col);
  if (gil_end_ == 0.0) {
    fail("gil() in a for loop whose end value is 0: it gives x0 + (xn - x0) x #n / end", col);
  }
  return first + (last - first) * parameters_.get(gil_var_) / gil_end_;
}

// "for #1=0 to 7 [step 1]" and "next [#1]", at the start of a line (after N).
bool BlockParser::read_nx_keyword(Block& block, int col) {
  const std::string_view rest = std::string_view(text_).substr(pos_);
  if (rest.starts_with("for#")) {
    if (block.nx_loop != Block::Loop::none) fail("Two loop words on one line", col);
    pos_ += 4;
    block.nx_loop = Block::Loop::for_;
    block.nx_loop_column = col;
    block.nx_loop_var = read_parameter_index();
    if (peek() != '=') error("Equal sign missing after the loop variable (for #1=0 to 7)");
    ++pos_;
    block.nx_loop_start = read_nx_expression();
    if (!match_text("to")) error("'to' missing in the for loop (for #1=0 to 7)");
    block.nx_loop_end = read_nx_expression();
    block.nx_loop_step = 1;
    if (match_text("step")) {
      const int step_column = column();
      block.nx_loop_step = read_nx_expression();
      if (block.nx_loop_step == 0.0) fail("Step 0 in a for loop never ends", step_column);
    }
    return true;
  }
  if (rest.starts_with("next")) {
    if (block.nx_loop != Block::Loop::none) fail("Two loop words on one line", col);
    pos_ += 4;
    block.nx_loop = Block::Loop::next;
    block.nx_loop_column = col;
    if (peek() == '#') {
      ++pos_;
      block.nx_loop_var = read_parameter_index();
    }
    return true;
  }
  return false;
}

// G in the Numeryx dialect: a bare g is g0; g10 is polar positioning; the drilling cycle words
// and g80 stand apart from the motion group, so that "g x10 g81 ..." positions and drills.
void BlockParser::read_nx_g(Block& block, int col) {
  const double value = read_nx_value();
  const double scaled = value * 10.0;
  const double code = std::nearbyint(scaled);
  if (std::fabs(scaled - code) > 0.001 || code < 0 || code > 999) {
    fail("Unknown g code used", col);
  }
  const int number = static_cast<int>(code);
  if (number == 100) {
    if (block.nx_polar) fail("Two g10 words on one line", col);
    block.nx_polar = true;
    block.nx_polar_column = col;
    return;
  }
  if (number == 800 || is_cycle_word(number)) {
    if (block.nx_cycle != -1) fail("Two drilling cycle words on one line", col);
    block.nx_cycle = number;
    block.nx_cycle_column = col;
    return;
  }
  if (number >= 870 && number <= 890) {
    fail("g" + std::to_string(number / 10) +
             " is no Numeryx drilling cycle (g73, g74, g81 to g86; g80 cancels)",
         col);
  }
  add_g(block, number, col);
}

}  // namespace cncd::interp
