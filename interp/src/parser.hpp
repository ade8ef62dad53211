// Reads one source line into a Block, evaluating expressions and parameter references with the
// parameter values as they were before the line (LinuxCNC semantics: assignments on a line take
// effect only after the whole line has been read).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "block.hpp"
#include "parameters.hpp"

namespace cncd::interp {

// Limits on what one value may be: brackets, unary functions and signs nest at most
// kMaxNesting deep, and a number written in the program is at most kMaxNumber in magnitude.
inline constexpr int kMaxNesting = 100;
inline constexpr double kMaxNumber = 1e300;

class BlockParser {
 public:
  explicit BlockParser(const Parameters& parameters) : parameters_(parameters) {}

  // Throws Failure with the column of the offending character.
  void parse(std::string_view line, Block& block);

 private:
  void normalize(std::string_view line);
  void read_comment(Block& block);
  void read_word(Block& block);
  void read_g(Block& block, int column);
  void read_m(Block& block, int column);
  void read_o(Block& block, int column);
  void read_program_number(Block& block);
  void read_assignment(Block& block);

  double read_real_value();
  double read_nested_value();
  double read_number();
  double read_expression();
  double read_unary(int column);
  double read_parameter_value();
  int read_parameter_index();
  int read_integer_value();
  void read_name(std::string& name);
  int read_binary_operator();

  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  char peek_at(std::size_t ahead) const {
    return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
  }
  int column() const;
  [[noreturn]] void error(std::string message) const;

  const Parameters& parameters_;
  std::string text_;          // lowercased, blanks removed outside comments
  std::vector<int> columns_;  // original 1-based column of each character of text_
  std::string comment_raw_;
  std::string name_;
  std::size_t pos_ = 0;
  int depth_ = 0;  // nesting of the value being read
  // Only block delete and a line number may come before an O-word (LinuxCNC: "Bad character
  // 'o' used" after anything else).
  bool o_allowed_ = true;
};

}  // namespace cncd::interp
