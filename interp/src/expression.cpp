// Expressions inside [ ]: LinuxCNC's binary operators and precedence, and its unary functions
// (trigonometry in degrees). Part of BlockParser: values come from the same line reader.
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "failure.hpp"
#include "parser.hpp"

namespace cncd::interp {
namespace {

enum class Op : int {
  none,
  power,
  times,
  divide,
  mod,
  plus,
  minus,
  eq,
  ne,
  gt,
  ge,
  lt,
  le,
  and_,
  or_,
  xor_
};

// LinuxCNC's precedence: ** > * / MOD > + - > comparisons > AND OR XOR; all left-associative.
int precedence(Op op) {
  if (op == Op::power) return 5;
  if (op == Op::times || op == Op::divide || op == Op::mod) return 4;
  if (op == Op::plus || op == Op::minus) return 3;
  if (op == Op::eq || op == Op::ne || op == Op::gt || op == Op::ge || op == Op::lt ||
      op == Op::le) {
    return 2;
  }
  if (op == Op::and_ || op == Op::or_ || op == Op::xor_) return 1;
  return 0;
}

// Degrees to radians and back as LinuxCNC converts them, through a long double pi (its
// sin, cos and tan then run in long double): the same last bits, so the same signs of zero.
constexpr long double kPiLong = 3.141592653589793238462643383279502884L;
long double to_radians(double degrees) {
  return degrees * kPiLong / 180.0;
}
double to_degrees(double radians) {
  return static_cast<double>(radians * 180.0 / kPiLong);
}
// LinuxCNC compares with this tolerance in EQ/NE/.. and when a real must be an integer.
constexpr double kTolerance = 0.0001;

}  // namespace

int BlockParser::read_binary_operator() {
  auto match = [this](const char* word) {
    std::size_t n = 0;
    while (word[n] != '\0') {
      if (peek_at(n) != word[n]) return false;
      ++n;
    }
    pos_ += n;
    return true;
  };
  const char c = peek();
  switch (c) {
    case '*':
      ++pos_;
      if (peek() == '*') {
        ++pos_;
        return static_cast<int>(Op::power);
      }
      return static_cast<int>(Op::times);
    case '/':
      ++pos_;
      return static_cast<int>(Op::divide);
    case '+':
      ++pos_;
      return static_cast<int>(Op::plus);
    case '-':
      ++pos_;
      return static_cast<int>(Op::minus);
    default:
      break;
  }
  static constexpr std::pair<const char*, Op> kWords[] = {
      {"mod", Op::mod}, {"eq", Op::eq}, {"ne", Op::ne},    {"gt", Op::gt},  {"ge", Op::ge},
      {"lt", Op::lt},   {"le", Op::le}, {"and", Op::and_}, {"or", Op::or_}, {"xor", Op::xor_},
  };
  for (const auto& [word, op] : kWords) {
    if (match(word)) return static_cast<int>(op);
  }
  if (c == '\0') error("Unclosed expression");
  if (std::string_view("aeglmnox").find(c) != std::string_view::npos)
    error(std::string("Unknown operation name starting with ") + c);
  error("Unknown operation");
}

namespace {
double apply(Op op, double left, double right, int column) {
  switch (op) {
    case Op::power:
      if (left < 0.0 && std::floor(right) != right) {
        fail("Attempt to raise negative to non integer power", column);
      }
      return std::pow(left, right);
    case Op::times:
      return left * right;
    case Op::divide:
      if (right == 0.0) fail("Attempt to divide by zero", column);
      return left / right;
    case Op::mod: {
      if (right == 0.0) fail("Attempt to divide by zero", column);
      double result = std::fmod(left, right);
      if (result < 0.0) result += std::fabs(right);
      return result;
    }
    case Op::plus:
      return left + right;
    case Op::minus:
      return left - right;
    case Op::eq:
      return std::fabs(left - right) < kTolerance ? 1.0 : 0.0;
    case Op::ne:
      return std::fabs(left - right) >= kTolerance ? 1.0 : 0.0;
    case Op::gt:
      return left > right ? 1.0 : 0.0;
    case Op::ge:
      return left >= right ? 1.0 : 0.0;
    case Op::lt:
      return left < right ? 1.0 : 0.0;
    case Op::le:
      return left <= right ? 1.0 : 0.0;
    case Op::and_:
      return (left == 0.0 || right == 0.0) ? 0.0 : 1.0;
    case Op::or_:
      return (left != 0.0 || right != 0.0) ? 1.0 : 0.0;
    case Op::xor_:
      return ((left == 0.0) != (right == 0.0)) ? 1.0 : 0.0;
    case Op::none:
      break;
  }
  return 0.0;
}

// Operator-precedence evaluation with explicit stacks, for the bracketed expressions and the
// Numeryx dialect's; expressions nest through the operand readers, not through this.
class OperatorStack {
 public:
  explicit OperatorStack(double first) { values_[0] = first; }

  // Applies the stacked operators that bind at least as tightly as `op`; false when there is
  // no room left to stack `op`.
  bool make_room_for(Op op) {
    while (top_ > 0 && precedence(ops_[top_ - 1]) >= precedence(op))
      apply_top();
    return top_ + 1 < kMaxDepth;
  }
  // `op` (read at `column`) and the operand after it.
  void push(Op op, int column, double operand) {
    ops_[top_] = op;
    op_columns_[top_] = column;
    values_[++top_] = operand;
  }
  double result() {
    while (top_ > 0)
      apply_top();
    return values_[0];
  }

 private:
  static constexpr int kMaxDepth = 16;
  void apply_top() {
    values_[top_ - 1] =
        apply(ops_[top_ - 1], values_[top_ - 1], values_[top_], op_columns_[top_ - 1]);
    --top_;
  }
  double values_[kMaxDepth];
  Op ops_[kMaxDepth];
  int op_columns_[kMaxDepth];
  int top_ = 0;
};

}  // namespace

double BlockParser::read_expression() {
  ++pos_;  // '['
  OperatorStack stack(read_real_value());
  for (;;) {
    if (peek() == ']') {
      ++pos_;
      return stack.result();
    }
    const int col = column();
    const Op op = static_cast<Op>(read_binary_operator());
    if (!stack.make_room_for(op)) error("Expression too complex");
    stack.push(op, col, read_real_value());
  }
}

// EXISTS[#<name>] is 1 while the named parameter is defined; EXISTS[#n], with n a number, a
// parameter (##1) or an expression (#[2+3]), is 1 for the numbers 1..5601 that a parameter
// may have, 0 for any other integer, as in rs274.
double BlockParser::read_exists() {
  ++pos_;  // '['
  if (peek() != '#') error("Expected # reading parameter");
  ++pos_;
  bool exists = false;
  if (peek() == '<') {
    read_name(name_);
    exists = parameters_.exists_named(name_);
  } else {
    const int col = column();
    const double value = read_real_value();
    const double number = std::nearbyint(value);
    if (std::fabs(value - number) > kTolerance) fail("Non integer value for integer", col);
    exists = number >= 1 && number < kMaxParameter;
  }
  if (peek() != ']') error("Expected ] reading bracketed parameter");
  ++pos_;
  return exists ? 1.0 : 0.0;
}

double BlockParser::read_unary(int col) {
  std::string_view rest(text_.data() + pos_, text_.size() - pos_);
  static constexpr const char* kNames[] = {"abs", "acos", "asin",  "atan", "cos",  "exp", "fix",
                                           "fup", "ln",   "round", "sin",  "sqrt", "tan", "exists"};
  std::string_view name;
  for (const char* candidate : kNames) {
    const std::string_view word(candidate);
    if (rest.substr(0, word.size()) == word && word.size() > name.size()) name = word;
  }
  // rs274's words: a name it knows without its bracket, a word that starts as one of its names
  // do, any other word.
  if (name.empty()) {
    if (std::string_view("aceflrst").find(rest.front()) != std::string_view::npos)
      fail(std::string("Unknown word starting with ") + rest.front(), col);
    fail("Unknown word where unary operation could be", col);
  }
  pos_ += name.size();
  if (peek() != '[') error("Left bracket missing after unary operation name");
  if (name == "exists") return read_exists();
  const double arg = read_expression();
  if (name == "atan") {
    if (peek() != '/') error("Slash missing after first atan argument");
    ++pos_;
    if (peek() != '[') error("Left bracket missing after slash with atan");
    const double x = read_expression();
    return to_degrees(std::atan2(arg, x));
  }
  if (name == "abs") return std::fabs(arg);
  if (name == "acos") {
    if (arg < -1.0 || arg > 1.0) fail("Argument to acos out of range", col);
    return to_degrees(std::acos(arg));
  }
  if (name == "asin") {
    if (arg < -1.0 || arg > 1.0) fail("Argument to asin out of range", col);
    return to_degrees(std::asin(arg));
  }
  if (name == "cos") return static_cast<double>(std::cos(to_radians(arg)));
  if (name == "exp") return std::exp(arg);
  if (name == "fix") return std::floor(arg);
  if (name == "fup") return std::ceil(arg);
  if (name == "ln") {
    if (arg <= 0.0) fail("Zero or negative argument to ln", col);
    return std::log(arg);
  }
  if (name == "round") return std::round(arg);
  if (name == "sin") return static_cast<double>(std::sin(to_radians(arg)));
  if (name == "sqrt") {
    if (arg < 0.0) fail("Negative argument to sqrt", col);
    return std::sqrt(arg);
  }
  return static_cast<double>(std::tan(to_radians(arg)));
}

// Numeryx: an expression written after '=' in an address or assignment ("x=gil(0,10)",
// "f=1000/13"), without brackets. It ends where a character that is no operator follows a value
// (the next address letter, a comma, the end of the line). Symbolic operators only, with
// LinuxCNC's precedence; words such as MOD would be read as addresses.
double BlockParser::read_nx_expression() {
  OperatorStack stack(read_nx_operand());
  for (;;) {
    const char c = peek();
    Op op = Op::none;
    const int col = column();
    if (c == '*' && peek_at(1) == '*') {
      op = Op::power;
      pos_ += 2;
    } else if (c == '*' || c == '/' || c == '+' || c == '-') {
      op = c == '*' ? Op::times : c == '/' ? Op::divide : c == '+' ? Op::plus : Op::minus;
      ++pos_;
    } else {
      break;
    }
    if (!stack.make_room_for(op)) error("Expression too complex");
    stack.push(op, col, read_nx_operand());
  }
  const double result = stack.result();
  if (!std::isfinite(result)) error("Result is not a finite number (overflow)");
  return result;
}

}  // namespace cncd::interp
