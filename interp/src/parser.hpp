// Reads one source line into a Block, evaluating expressions and parameter references with the
// parameter values as they were before the line (LinuxCNC semantics: assignments on a line take
// effect only after the whole line has been read).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "block.hpp"
#include "cncd/interp/interpreter.hpp"
#include "parameters.hpp"

namespace cncd::interp {

// Limits on what one value may be: brackets, unary functions and signs nest at most
// kMaxNesting deep, and a number written in the program is at most kMaxNumber in magnitude.
inline constexpr int kMaxNesting = 100;
inline constexpr double kMaxNumber = 1e300;
// LinuxCNC's tolerance when a real must be an integer.
inline constexpr double kIntegerTolerance = 0.0001;

// The O-word keyword `word` starts with ("callsub" is "call" followed by junk, as LinuxCNC
// reads it), and its length in `matched`; none when it starts with no keyword.
OKind match_o_keyword(std::string_view word, std::size_t& matched);

class BlockParser {
 public:
  explicit BlockParser(const Parameters& parameters) : parameters_(parameters) {}

  // Throws Failure with the column of the offending character.
  void parse(std::string_view line, Block& block);

  // The O-word of a line that is being skipped or searched: its name, evaluated when it is a
  // parameter or an expression (rs274 evaluates it even there), and its keyword (kind none
  // when it has none; matched as a prefix, an unknown one refused). Nothing after the keyword
  // is read. False without an O-word.
  bool read_o_head(std::string_view line, std::string& name, OKind& kind);

  // The syntax to read: LinuxCNC's, or the Numeryx dialect's (see numeryx_parser.cpp).
  void set_dialect(Dialect dialect) { dialect_ = dialect; }
  // Numeryx: the innermost for loop, whose variable and end value gil() reads; var 0 = none.
  void set_gil_loop(int var, double end) {
    gil_var_ = var;
    gil_end_ = end;
  }

 private:
  void normalize(std::string_view line);
  void read_comment(Block& block);
  void read_word(Block& block);
  void read_g(Block& block, int column);
  void add_g(Block& block, int number, int column);
  void read_m(Block& block, int column);
  void read_o(Block& block, int column);
  void read_o_name(std::string& name);
  void read_program_number(Block& block);
  void read_assignment(Block& block);

  // Numeryx dialect (numeryx_parser.cpp).
  bool read_nx_keyword(Block& block, int column);
  void read_nx_g(Block& block, int column);
  double read_nx_value();
  double read_nx_expression();
  double read_nx_operand();
  double read_gil(int column);
  bool nx_value_follows() const;
  bool match_text(std::string_view word);

  double read_real_value();
  double read_nested_value();
  double read_number();
  double read_expression();
  double read_unary(int column);
  double read_exists();
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
  Dialect dialect_ = Dialect::linuxcnc;
  int gil_var_ = 0;
  double gil_end_ = 0;
};

}  // namespace cncd::interp
