#include "source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "failure.hpp"

namespace cncd::interp {
namespace {
constexpr std::size_t kBufferSize = 64 * 1024;
}

LineSource::~LineSource() {
  if (file_ != nullptr) std::fclose(file_);
}

LineSource::LineSource(LineSource&& other) noexcept {
  *this = std::move(other);
}

LineSource& LineSource::operator=(LineSource&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = std::exchange(other.file_, nullptr);
    is_text_ = std::exchange(other.is_text_, false);
    text_ = std::move(other.text_);
    name_ = std::move(other.name_);
    buffer_ = std::move(other.buffer_);
    buffer_pos_ = other.buffer_pos_;
    buffer_len_ = other.buffer_len_;
    offset_ = other.offset_;
    line_number_ = other.line_number_;
  }
  return *this;
}

std::string LineSource::open_file(const std::filesystem::path& path) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  // O_NONBLOCK: opening a FIFO with no writer would wait for ever.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  std::string problem;
  struct stat st {};
  if (fd < 0) {
    problem = std::strerror(errno);
  } else if (::fstat(fd, &st) != 0) {
    problem = std::strerror(errno);
  } else if (S_ISDIR(st.st_mode)) {
    problem = std::strerror(EISDIR);
  } else if (!S_ISREG(st.st_mode)) {
    problem = S_ISFIFO(st.st_mode) ? "it is a FIFO, not a regular file" : "not a regular file";
  } else if (::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0 ||
             (file_ = ::fdopen(fd, "rb")) == nullptr) {
    problem = std::strerror(errno);
  }
  if (file_ == nullptr && fd >= 0) ::close(fd);
  is_text_ = false;
  name_ = path.string();
  buffer_.resize(kBufferSize);
  buffer_pos_ = buffer_len_ = 0;
  offset_ = 0;
  line_number_ = 0;
  return problem;
}

void LineSource::open_text(std::string text, std::string name) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  is_text_ = true;
  text_ = std::move(text);
  name_ = std::move(name);
  offset_ = 0;
  line_number_ = 0;
}

bool LineSource::fill() {
  buffer_len_ = std::fread(buffer_.data(), 1, buffer_.size(), file_);
  buffer_pos_ = 0;
  return buffer_len_ > 0;
}

bool LineSource::read_line(std::string& line) {
  line.clear();
  const std::int64_t line_start = offset_;
  if (is_text_) {
    const auto start = static_cast<std::size_t>(offset_);
    if (start >= text_.size()) return false;
    std::size_t end = text_.find('\n', start);
    const std::size_t next = end == std::string::npos ? text_.size() : end + 1;
    if (end == std::string::npos) end = text_.size();
    if (end - start > kMaxLineLength + 1) too_long(line_start);
    line.assign(text_, start, end - start);
    offset_ = static_cast<std::int64_t>(next);
  } else {
    if (file_ == nullptr) return false;
    bool any = false;
    for (;;) {
      if (buffer_pos_ >= buffer_len_ && !fill()) break;
      any = true;
      const char* begin = buffer_.data() + buffer_pos_;
      const std::size_t available = buffer_len_ - buffer_pos_;
      const void* found = std::memchr(begin, '\n', available);
      if (found != nullptr) {
        const auto count = static_cast<std::size_t>(static_cast<const char*>(found) - begin);
        if (line.size() + count > kMaxLineLength + 1)
          too_long(line_start);  // +1: a '\r' before '\n'
        line.append(begin, count);
        buffer_pos_ += count + 1;
        offset_ += static_cast<std::int64_t>(count + 1);
        break;
      }
      if (line.size() + available > kMaxLineLength + 1) too_long(line_start);
      line.append(begin, available);
      buffer_pos_ += available;
      offset_ += static_cast<std::int64_t>(available);
    }
    if (!any) return false;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.size() > kMaxLineLength) too_long(line_start);
  ++line_number_;
  return true;
}

// The line is left unread: every later read of this source fails on it the same way.
void LineSource::too_long(std::int64_t line_start) {
  const int number = line_number_ + 1;
  seek(line_start, line_number_);
  throw Failure{"Line is longer than " + std::to_string(kMaxLineLength) +
                    " characters (the longest line a program may have)",
                0, name_, number};
}

void LineSource::seek(std::int64_t offset, int line_number_before) {
  offset_ = offset;
  line_number_ = line_number_before;
  if (file_ != nullptr) {
    std::fseek(file_, static_cast<long>(offset), SEEK_SET);
    buffer_pos_ = buffer_len_ = 0;
  }
}

}  // namespace cncd::interp
