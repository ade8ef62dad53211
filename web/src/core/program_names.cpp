// What a program may be called, and the decoding of names taken from URLs.
#include <unistd.h>

#include "cncd/web/program_dir.hpp"

namespace cncd::web {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string check_program_name(std::string_view name) {
  if (name.empty()) return "the name is empty";
  if (name == "." || name == "..") return "'" + std::string(name) + "' is not a file name";
  for (const char c : name) {
    if (c == '/') return "the name contains '/': it must be one file name, without directories";
    if (c == '\0') return "the name contains a NUL character";
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) return "the name contains a control character";
  }
  if (name.front() == '.') return "the name starts with '.' (hidden files are not programs)";
  if (name.size() > 255) {
    return "the name is " + std::to_string(name.size()) + " bytes long; at most 255 are allowed";
  }
  return "";
}

Decoded percent_decode(std::string_view segment) {
  Decoded out;
  out.text.reserve(segment.size());
  for (std::size_t i = 0; i < segment.size(); ++i) {
    if (segment[i] != '%') {
      out.text += segment[i];
      continue;
    }
    const int high = i + 2 < segment.size() ? hex_value(segment[i + 1]) : -1;
    const int low = high >= 0 ? hex_value(segment[i + 2]) : -1;
    if (high < 0 || low < 0) {
      out.error = "a '%' not followed by two hex digits";
      out.text.clear();
      return out;
    }
    if (high == 0 && low == 0) {
      out.error = "%00 (a NUL character)";
      out.text.clear();
      return out;
    }
    out.text += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return out;
}

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) reset(other.release());
  return *this;
}

void UniqueFd::reset(int fd) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
}

}  // namespace cncd::web
