#include "source.hpp"

#include <cstring>
#include <utility>

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

bool LineSource::open_file(const std::filesystem::path& path) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = std::fopen(path.c_str(), "rb");
  is_text_ = false;
  name_ = path.string();
  buffer_.resize(kBufferSize);
  buffer_pos_ = buffer_len_ = 0;
  offset_ = 0;
  line_number_ = 0;
  return file_ != nullptr;
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
  if (is_text_) {
    const auto start = static_cast<std::size_t>(offset_);
    if (start >= text_.size()) return false;
    std::size_t end = text_.find('\n', start);
    const std::size_t next = end == std::string::npos ? text_.size() : end + 1;
    if (end == std::string::npos) end = text_.size();
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
        line.append(begin, count);
        buffer_pos_ += count + 1;
        offset_ += static_cast<std::int64_t>(count + 1);
        break;
      }
      line.append(begin, available);
      buffer_pos_ += available;
      offset_ += static_cast<std::int64_t>(available);
    }
    if (!any) return false;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  ++line_number_;
  return true;
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
