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

// (DEBUG, ...) text with #n and #<name> replaced by their values, as LinuxCNC does: six
// decimals, "######" for an unknown name; anything else after '#' stays as written.
std::string Interpreter::Impl::substitute_parameters(const std::string& text) const {
  std::string out;
  char number[64];
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c != '#' || i + 1 >= text.size()) {
      out.push_back(c);
      continue;
    }
    if (text[i + 1] == '<') {
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
      const auto value = parameters_.get_named(name);
      if (value) {
        std::snprintf(number, sizeof number, "%f", *value);
        out += number;
      } else {
        out += "######";
      }
      i = close;
      continue;
    }
    std::size_t k = i + 1;
    int index = 0;
    while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k])) && index < 100000) {
      index = index * 10 + (text[k] - '0');
      ++k;
    }
    if (k == i + 1 || index < 1 || index >= kMaxParameter) {
      out.push_back(c);
      continue;
    }
    std::snprintf(number, sizeof number, "%f", parameters_.get(index));
    out += number;
    i = k - 1;
  }
  return out;
}

}  // namespace cncd::interp
