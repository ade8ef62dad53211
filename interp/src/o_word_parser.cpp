// Reading O-words: the name (a number, <name>, or a parameter or expression whose value is the
// number), the keyword and what the keyword takes.
#include <climits>
#include <cmath>

#include "failure.hpp"
#include "parser.hpp"

namespace cncd::interp {
namespace {

bool is_alpha(char c) {
  return c >= 'a' && c <= 'z';
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

}  // namespace

OKind match_o_keyword(std::string_view word, std::size_t& matched) {
  struct Entry {
    const char* word;
    OKind kind;
  };
  static constexpr Entry kWords[] = {
      {"sub", OKind::sub},        {"endsub", OKind::endsub}, {"call", OKind::call},
      {"do", OKind::do_},         {"while", OKind::while_},  {"endwhile", OKind::endwhile},
      {"if", OKind::if_},         {"elseif", OKind::elseif}, {"else", OKind::else_},
      {"endif", OKind::endif},    {"break", OKind::break_},  {"continue", OKind::continue_},
      {"return", OKind::return_}, {"repeat", OKind::repeat}, {"endrepeat", OKind::endrepeat},
  };
  OKind kind = OKind::none;
  matched = 0;
  for (const auto& entry : kWords) {
    const std::string_view keyword(entry.word);
    if (keyword.size() > matched && word.substr(0, keyword.size()) == keyword) {
      kind = entry.kind;
      matched = keyword.size();
    }
  }
  return kind;
}

// rs274 names a numbered O-word by its integer value: o0100, o100, o[50*2] and o#1 with #1 =
// 100.00001 are all o100; o[-1] is o<-1>.
void BlockParser::read_o_name(std::string& name) {
  name.clear();
  const char c = peek();
  if (c == '<') {
    ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '>')
      name.push_back(text_[pos_++]);
    if (peek() != '>') error("Named parameter not terminated");
    ++pos_;
    return;
  }
  if (c == '#' || c == '[') {
    const int col = column();
    const double value = read_real_value();
    const double rounded = std::nearbyint(value);
    if (std::fabs(value - rounded) > kIntegerTolerance) fail("Non integer value for integer", col);
    // rs274 turns a larger value into INT_MIN: o[3e9] would call o<-2147483648>.
    if (std::fabs(rounded) > INT_MAX) {
      fail("O-word number out of range (at most " + std::to_string(INT_MAX) + " in size)", col);
    }
    name = std::to_string(static_cast<int>(rounded));  // -0.00001 is o0, not o-0
    return;
  }
  if (!is_digit(c)) error("Bad format of o-word");
  while (peek() == '0' && is_digit(peek_at(1)))
    ++pos_;
  while (is_digit(peek()))
    name.push_back(text_[pos_++]);
}

void BlockParser::read_o(Block& block, int col) {
  block.o_column = col;
  read_o_name(block.o_name);
  std::string keyword;
  while (is_alpha(peek()))
    keyword.push_back(text_[pos_++]);
  if (keyword.empty()) {
    read_program_number(block);
    return;
  }
  std::size_t matched = 0;
  block.o_kind = match_o_keyword(keyword, matched);
  if (block.o_kind == OKind::none) fail("Unknown control command in o word", col);
  if (matched < keyword.size()) fail("Unexpected character after O-word", col);
  switch (block.o_kind) {
    case OKind::call:
      // Comments may come before and between the arguments.
      for (;;) {
        if (peek() == '(') {
          read_comment(block);
        } else if (peek() == '[') {
          block.call_args.push_back(read_expression());
        } else {
          break;
        }
      }
      break;
    case OKind::while_:
    case OKind::if_:
    case OKind::elseif:
    case OKind::repeat:
      if (peek() != '[') error("Left bracket missing after '" + keyword + "'");
      block.o_value = read_expression();
      block.has_o_value = true;
      break;
    case OKind::return_:
    case OKind::endsub:
      if (peek() == '[') {
        block.o_value = read_expression();
        block.has_o_value = true;
      }
      break;
    default:
      break;
  }
  // Only comments may follow, as in rs274: the line's other words would be skipped unseen.
  while (pos_ < text_.size()) {
    if (peek() != '(' && peek() != ';') error("Unexpected character after O-word");
    read_comment(block);
  }
}

void BlockParser::read_program_number(Block& block) {
  // A bare O-word is a program number (Fanuc posts start with "O1234 (NAME)"): LinuxCNC
  // ignores it, and the comments after it too (no message, no comment); anything else after
  // it is refused.
  const int comments_before = block.comment_count;
  if (pos_ < text_.size() && peek() != '(' && peek() != ';') {
    error("Unknown control command in o word");  // rs274's words for "o<name> [1]" without call
  }
  while (pos_ < text_.size()) {
    if (peek() != '(' && peek() != ';') error("Unexpected character after O-word");
    read_comment(block);
  }
  block.comment_count = comments_before;
  block.o_kind = OKind::none;
}

bool BlockParser::read_o_head(std::string_view line, std::string& name, OKind& kind) {
  normalize(line);
  pos_ = 0;
  depth_ = 0;
  kind = OKind::none;
  if (peek() == '/') ++pos_;
  if (peek() == 'n') {
    ++pos_;
    while (is_digit(peek()) || peek() == '.')
      ++pos_;
  }
  if (peek() != 'o') return false;
  ++pos_;
  read_o_name(name);
  std::string keyword;
  while (is_alpha(peek()))
    keyword.push_back(text_[pos_++]);
  // As scan_o_word reads a numbered or named O-word: a keyword is matched as a prefix.
  std::size_t matched = 0;
  kind = match_o_keyword(keyword, matched);
  if (!keyword.empty() && kind == OKind::none) fail("Unknown control command in o word");
  return true;
}

}  // namespace cncd::interp
