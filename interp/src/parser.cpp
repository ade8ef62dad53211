#include "parser.hpp"

#include <charconv>
#include <cmath>

#include "failure.hpp"

namespace cncd::interp {
namespace {

constexpr double kTolerance = kIntegerTolerance;

bool is_alpha(char c) {
  return c >= 'a' && c <= 'z';
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

}  // namespace

int BlockParser::column() const {
  if (pos_ < columns_.size()) return columns_[pos_];
  return columns_.empty() ? 1 : columns_.back() + 1;
}

void BlockParser::error(std::string message) const {
  fail(std::move(message), column());
}

void BlockParser::normalize(std::string_view line) {
  text_.clear();
  columns_.clear();
  bool in_comment = false;
  int function_depth = 0;  // Numeryx: inside gil( ... ), whose brackets are no comment
  for (std::size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    const int col = static_cast<int>(i) + 1;
    if (dialect_ == Dialect::numeryx && !in_comment &&
        ((c == '(' && (function_depth > 0 || text_.ends_with("gil"))) ||
         (c == ')' && function_depth > 0))) {
      function_depth += c == '(' ? 1 : -1;
      text_.push_back(c);
      columns_.push_back(col);
      continue;
    }
    if (in_comment) {
      if (c == ')') in_comment = false;
      text_.push_back(c);
      columns_.push_back(col);
      continue;
    }
    if (c == ';') {
      // The rest of the line is a comment; keep it verbatim behind a marker.
      text_.append(line.substr(i));
      for (std::size_t k = i; k < line.size(); ++k)
        columns_.push_back(static_cast<int>(k) + 1);
      return;
    }
    if (c == ' ' || c == '\t') continue;
    if (c == '(') in_comment = true;
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    text_.push_back(c);
    columns_.push_back(col);
  }
}

void BlockParser::parse(std::string_view line, Block& block) {
  block.clear();
  normalize(line);
  pos_ = 0;
  depth_ = 0;
  o_allowed_ = true;
  if (peek() == '/') {
    block.block_delete = true;
    ++pos_;
  }
  while (pos_ < text_.size())
    read_word(block);
}

void BlockParser::read_comment(Block& block) {
  const bool semicolon = peek() == ';';
  const int start_column = column();
  ++pos_;
  comment_raw_.clear();
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (!semicolon && c == ')') break;
    if (!semicolon && c == '(') error("Nested comment found");
    comment_raw_.push_back(c);
    ++pos_;
  }
  if (semicolon) return;  // LinuxCNC emits nothing for ';' comments
  if (pos_ >= text_.size()) fail("Unclosed comment found", start_column);
  ++pos_;
  const auto index = static_cast<std::size_t>(block.comment_count++);
  if (block.comments.size() <= index) block.comments.emplace_back();
  block.comments[index] = comment_raw_;
}

void BlockParser::read_word(Block& block) {
  const char c = peek();
  const int col = column();
  if (c == 'o' && !o_allowed_) error("Bad character 'o' used");
  o_allowed_ = o_allowed_ && c == 'n';
  if (c == '(' || c == ';') {
    read_comment(block);
    return;
  }
  if (c == '#') {
    read_assignment(block);
    return;
  }
  if (c == '@' || c == '^') {
    ++pos_;
    bool& seen = c == '@' ? block.has_polar_distance : block.has_polar_angle;
    if (seen) fail(std::string("Multiple ") + c + " words on one line", col);
    seen = true;
    (c == '@' ? block.polar_distance : block.polar_angle) = read_real_value();
    return;
  }
  if (!is_alpha(c)) {
    error(std::string("Bad character '") + c + "' used");
  }
  const bool numeryx = dialect_ == Dialect::numeryx;
  if (numeryx && (c == 'f' || c == 'n') && read_nx_keyword(block, col)) return;
  ++pos_;
  switch (c) {
    case 'g':
      if (numeryx) {
        read_nx_g(block, col);
      } else {
        read_g(block, col);
      }
      return;
    case 'm':
      read_m(block, col);
      return;
    case 'o':
      read_o(block, col);
      return;
    case 'n': {
      if (block.has_line_number) fail("Multiple n words on one line", col);
      block.has_line_number = true;
      block.line_number = read_real_value();
      return;
    }
    default:
      break;
  }
  const auto index = static_cast<std::size_t>(c - 'a');
  if (numeryx && Block::nx_cycle_slot(c) >= 0 && block.nx_cycle > 0 && block.nx_cycle != 800) {
    // R, Z, Q and D after the cycle word are the cycle's own.
    const auto slot = static_cast<std::size_t>(Block::nx_cycle_slot(c));
    if ((block.nx_cycle_present >> slot) & 1U) {
      fail(std::string("Multiple ") + c + " words after the cycle word on one line", col);
    }
    block.nx_cycle_value[slot] = read_nx_value();
    block.nx_cycle_col[slot] = col;
    block.nx_cycle_present = static_cast<std::uint8_t>(block.nx_cycle_present | (1U << slot));
    return;
  }
  if (block.present & (1U << index)) {
    fail(std::string("Multiple ") + c + " words on one line", col);
  }
  double value = 0;
  if (numeryx) {
    value = read_nx_value();
    if (c == 'l' || c == 't' || c == 'h') {
      const double rounded = std::nearbyint(value);
      if (std::fabs(value - rounded) > kTolerance || std::fabs(rounded) > 2e9) {
        fail("Non integer value for integer", col);
      }
      if (rounded < 0) fail(std::string("Negative ") + c + " word used", col);
      value = rounded;
    }
  } else if (c == 'l' || c == 't' || c == 'h') {
    // Integer words.
    value = read_integer_value();
    if (value < 0) fail(std::string("Negative ") + c + " word used", col);
  } else {
    value = read_real_value();
  }
  block.present |= 1U << index;
  block.value[index] = value;
  block.column[index] = col;
}

void BlockParser::read_g(Block& block, int col) {
  const double value = read_real_value();
  const double scaled = value * 10.0;
  const double code = std::nearbyint(scaled);
  if (std::fabs(scaled - code) > kTolerance * 10.0 || code < 0 || code > 999) {
    fail("Unknown g code used", col);
  }
  add_g(block, static_cast<int>(code), col);
}

void BlockParser::add_g(Block& block, int number, int col) {
  const CodeInfo info = g_code_info(number);
  if (info.group < 0) fail("Unknown g code used", col);
  const auto group = static_cast<std::size_t>(info.group);
  if (block.g[group] != -1) {
    // LinuxCNC lets G80 share a line with another motion code, which then wins.
    const bool g80_pair = info.group == static_cast<std::int8_t>(GGroup::motion) &&
                          (block.g[group] == 800 || number == 800);
    if (!g80_pair) fail("Two g codes used from same modal group", col);
    if (number == 800) return;
  }
  block.g[group] = number;
  block.g_column[group] = col;
}

void BlockParser::read_m(Block& block, int col) {
  const int number = read_integer_value();
  if (number < 0) fail("Negative m code used", col);
  const CodeInfo info = m_code_info(number);
  // Above M199 only M428 and M429 (the TCP switch, as LinuxCNC's samples remap them).
  if (number > 199 && info.group < 0)
    fail("M-code greater than 199: M" + std::to_string(number), col);
  if (info.group < 0) fail("Unknown m code used: M" + std::to_string(number), col);
  const auto group = static_cast<std::size_t>(info.group);
  if (block.m[group] != -1) fail("Two m codes used from same modal group", col);
  if (++block.m_count > 4) fail("Too many m codes on line", col);
  block.m[group] = number;
  block.m_column[group] = col;
}

void BlockParser::read_assignment(Block& block) {
  const int col = column();
  ++pos_;  // '#'
  if (peek() == '<') {
    const auto index = static_cast<std::size_t>(block.named_assignment_count++);
    if (block.named_assignments.size() <= index) block.named_assignments.emplace_back();
    // Read the name straight into the block: the value may name other parameters.
    read_name(block.named_assignments[index].first);
    if (peek() != '=') error("Equal sign missing in parameter setting");
    ++pos_;
    block.named_assignments[index].second =
        dialect_ == Dialect::numeryx ? read_nx_expression() : read_real_value();
    return;
  }
  const int number = read_parameter_index();
  if (peek() != '=') error("Equal sign missing in parameter setting");
  ++pos_;
  const double value = dialect_ == Dialect::numeryx ? read_nx_expression() : read_real_value();
  block.numbered_assignments.push_back({number, value, col});
}

void BlockParser::read_name(std::string& name) {
  ++pos_;  // '<'
  name.clear();
  while (pos_ < text_.size() && text_[pos_] != '>')
    name.push_back(text_[pos_++]);
  if (peek() != '>') error("Named parameter not terminated");
  ++pos_;
}

int BlockParser::read_parameter_index() {
  const int col = column();
  const int number = read_integer_value();
  if (number < 1 || number >= kMaxParameter) fail("Parameter number out of range", col);
  return number;
}

double BlockParser::read_parameter_value() {
  ++pos_;  // '#'
  if (peek() == '<') {
    const int col = column();
    read_name(name_);
    const auto value = parameters_.get_named(name_);
    if (!value) fail("Named parameter #<" + name_ + "> not defined", col);
    return *value;
  }
  const int col = column();
  const int number = read_parameter_index();
  if (number >= 5420 && number <= 5428 && parameters_.position_hidden()) {
    fail("Cannot read current position with cutter radius compensation on", col);
  }
  return parameters_.get(number);
}

int BlockParser::read_integer_value() {
  const int col = column();
  const double value = read_real_value();
  const double rounded = std::nearbyint(value);
  if (std::fabs(value - rounded) > kTolerance || std::fabs(rounded) > 2e9) {
    fail("Non integer value for integer", col);
  }
  return static_cast<int>(rounded);
}

// Every value, however nested, passes here: the nesting depth and the result are checked once.
double BlockParser::read_real_value() {
  if (++depth_ > kMaxNesting) {
    error("Expression nested too deeply (more than " + std::to_string(kMaxNesting) + " levels)");
  }
  const double value = read_nested_value();
  --depth_;
  if (!std::isfinite(value)) error("Result is not a finite number (overflow)");
  return value;
}

double BlockParser::read_nested_value() {
  const char c = peek();
  if (c == '[') return read_expression();
  if (c == '#') return read_parameter_value();
  if (is_alpha(c)) return read_unary(column());
  if ((c == '-' || c == '+') && (peek_at(1) == '[' || peek_at(1) == '#' || is_alpha(peek_at(1)))) {
    ++pos_;
    const double value = read_real_value();
    return c == '-' ? -value : value;
  }
  return read_number();
}

double BlockParser::read_number() {
  const std::size_t start = pos_;
  bool negative = false;
  if (peek() == '-' || peek() == '+') {
    negative = peek() == '-';
    ++pos_;
  }
  const std::size_t digits_start = pos_;
  bool seen_digit = false;
  bool seen_point = false;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (is_digit(c)) {
      seen_digit = true;
    } else if (c == '.' && !seen_point) {
      seen_point = true;
    } else {
      break;
    }
    ++pos_;
  }
  if (!seen_digit) {
    const std::string text = text_.substr(start, pos_ - start);
    pos_ = start;
    error("bad number format (conversion failed) parsing '" + text + "'");
  }
  double value = 0;
  const char* first = text_.data() + digits_start;
  const char* last = text_.data() + pos_;
  if (*first == '.') {
    // from_chars needs a digit before the point: ".5" is parsed as the fraction alone.
    std::string padded = "0";
    padded.append(first, last);
    if (std::from_chars(padded.data(), padded.data() + padded.size(), value).ec != std::errc()) {
      value = HUGE_VAL;
    }
  } else if (std::from_chars(first, last, value).ec != std::errc()) {
    value = HUGE_VAL;  // out of range
  }
  if (!(std::fabs(value) <= kMaxNumber)) {
    pos_ = start;
    error("Number too large (more than 1e300)");
  }
  return negative ? -value : value;
}

}  // namespace cncd::interp
