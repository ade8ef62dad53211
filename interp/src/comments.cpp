// What a comment does: (MSG,...) and (DEBUG,...) show a message, (ABORT,...) stops the
// program with one, (PRINT,...) and (LOG...) are for the operator's terminal and log file,
// (PROBEOPEN ...) opens the probe file; any other comment goes to the machine as it is.
#include <cctype>
#include <cstdio>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

bool starts_with_word(const std::string& text, const char* word, std::size_t& rest) {
  std::size_t i = 0;
  for (; word[i] != '\0'; ++i) {
    if (i >= text.size()) return false;
    if (std::tolower(static_cast<unsigned char>(text[i])) != word[i]) return false;
  }
  rest = i;
  return true;
}

}  // namespace

void Interpreter::Impl::do_comment() {
  if (block_.comment_count == 0) return;
  // LinuxCNC acts on the last comment of a line only, and reads its word after any blanks.
  const std::string& text = block_.comments[static_cast<std::size_t>(block_.comment_count - 1)];
  const std::size_t first = text.find_first_not_of(" \t");
  const std::string plain = first == std::string::npos ? std::string() : text.substr(first);
  std::size_t rest = 0;
  if (starts_with_word(plain, "msg,", rest)) {
    emit(Message{plain.substr(rest)});
    return;
  }
  if (starts_with_word(plain, "debug,", rest)) {
    emit(Message{substitute_parameters(plain.substr(rest))});
    return;
  }
  if (starts_with_word(plain, "abort,", rest)) {
    // The message is the error, as rs274 reports it (with the blank after the comma). rs274
    // says "Unknown error, bad error code" for an empty one.
    std::string message = substitute_parameters(plain.substr(rest));
    if (message.empty()) message = "Program aborted by an (ABORT,) comment without a message";
    fail(std::move(message));
  }
  // PRINT and LOG comments go to the operator's terminal or a log file, not to the machine.
  if (starts_with_word(plain, "print,", rest) || starts_with_word(plain, "log", rest)) return;
  probe_file_comment(plain);
  emit_comment(plain);
}

// (DEBUG, ...) and (ABORT, ...) text with #n and #<name> replaced by their values, as rs274
// does: "######" for an unknown name or a value too long to show; anything else after '#' stays as
// written. A value has six decimals unless a format before it in the comment says otherwise: %d
// none, %f four, %.Nf N (one digit). rs274 drops the '%' of a "%." that makes no format, and keeps
// any other '%'.
std::string Interpreter::Impl::substitute_parameters(const std::string& text) const {
  std::string out;
  char number[400];  // %.9f of 1e300, the largest value a program can write, fits
  int decimals = 6;
  auto put = [&](double value) {
    // rs274 shows a value of more than 29 characters (beyond 1e21 or so) as "######".
    const int length = std::snprintf(number, sizeof number, "%.*f", decimals, value);
    out += length <= 29 ? number : "######";
  };
  auto is_digit = [&](std::size_t k) {
    return k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]));
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    if (c == '%' && (next == 'd' || next == 'f')) {
      decimals = next == 'd' ? 0 : 4;
      ++i;
      continue;
    }
    if (c == '%' && next == '.') {
      if (is_digit(i + 2) && i + 3 < text.size() && text[i + 3] == 'f') {
        decimals = text[i + 2] - '0';
        i += 3;
      }
      continue;
    }
    if (c != '#' || i + 1 >= text.size()) {
      out.push_back(c);
      continue;
    }
    if (next == '<') {
      const std::size_t close = text.find('>', i + 2);
      if (close == std::string::npos) {
        out.push_back(c);
        continue;
      }
      std::string name;
      for (std::size_t k = i + 2; k < close; ++k) {
        if (text[k] != ' ' && text[k] != '\t') {
          name.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(text[k]))));
        }
      }
      if (const auto value = parameters_.get_named(name)) {
        put(*value);
      } else {
        out += "######";
      }
      i = close;
      continue;
    }
    std::size_t k = i + 1;
    int index = 0;
    while (is_digit(k) && index < 100000) {
      index = index * 10 + (text[k] - '0');
      ++k;
    }
    if (k == i + 1 || index < 1 || index >= kMaxParameter) {
      out.push_back(c);
      continue;
    }
    put(parameters_.get(index));
    i = k - 1;
  }
  return out;
}

}  // namespace cncd::interp
