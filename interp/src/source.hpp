// Incremental line reader over a program file or an in-memory text. Keeps one fixed buffer so
// memory does not depend on program length; offsets allow O-word loops and subroutine calls to
// jump back.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace cncd::interp {

class LineSource {
 public:
  LineSource() = default;
  ~LineSource();
  LineSource(const LineSource&) = delete;
  LineSource& operator=(const LineSource&) = delete;
  LineSource(LineSource&& other) noexcept;
  LineSource& operator=(LineSource&& other) noexcept;

  // The longest line a program may have, in bytes without its line end (LinuxCNC's is 256):
  // a longer one is an error, read without holding more than this in memory.
  static constexpr std::size_t kMaxLineLength = 4096;

  // Opens a regular file, never waiting (a FIFO is refused, not read). Returns "" or why it
  // cannot be opened.
  std::string open_file(const std::filesystem::path& path);
  void open_text(std::string text, std::string name);

  // Reads the next line (without its line terminator) into `line`. Returns false at end.
  // Throws Failure, naming this source and the line, for a line over kMaxLineLength.
  bool read_line(std::string& line);
  // Offset of the next line to read and its 1-based line number.
  std::int64_t tell() const { return offset_; }
  int next_line_number() const { return line_number_ + 1; }
  // Restarts reading at an offset previously returned by tell().
  void seek(std::int64_t offset, int line_number_before);
  int line_number() const { return line_number_; }
  const std::string& name() const { return name_; }
  bool is_open() const { return file_ != nullptr || is_text_; }

 private:
  bool fill();
  [[noreturn]] void too_long(std::int64_t line_start);

  std::FILE* file_ = nullptr;
  bool is_text_ = false;
  std::string text_;
  std::string name_;
  std::string buffer_;
  std::size_t buffer_pos_ = 0;
  std::size_t buffer_len_ = 0;
  std::int64_t offset_ = 0;
  int line_number_ = 0;
};

// A line of blanks and one '%': the marks that may open and close a program.
inline bool is_percent_line(const std::string& line) {
  bool percent = false;
  for (const char c : line) {
    if (c == ' ' || c == '\t') continue;
    if (c == '%' && !percent) {
      percent = true;
      continue;
    }
    return false;
  }
  return percent;
}

}  // namespace cncd::interp
