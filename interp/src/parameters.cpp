#include "parameters.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string_view>

#include "cncd/interp/stored_values.hpp"
#include "failure.hpp"

namespace cncd::interp {

bool is_persistent_parameter(int number) {
  // 5161-5390: G28/G30 homes, G92 offsets and the nine coordinate systems (LinuxCNC's list).
  return number >= 5161 && number <= 5390;
}

Parameters::Parameters() : numbered_(kMaxParameter, 0.0), scopes_(1) {}

std::optional<double> Parameters::get_named(std::string_view name) const {
  if (!name.empty() && name.front() == '_') {
    if (predefined_) {
      if (auto value = predefined_(name)) return value;
    }
    const auto it = globals_.find(std::string(name));
    if (it == globals_.end()) return std::nullopt;
    return it->second;
  }
  const auto& locals = scopes_.back();
  const auto it = locals.find(std::string(name));
  if (it == locals.end()) return std::nullopt;
  return it->second;
}

bool Parameters::exists_named(std::string_view name) const {
  return get_named(name).has_value();
}

void Parameters::set_named(std::string_view name, double value) {
  if (!name.empty() && name.front() == '_') {
    globals_.insert_or_assign(std::string(name), value);
  } else {
    scopes_.back().insert_or_assign(std::string(name), value);
  }
}

void Parameters::push_scope() {
  scopes_.emplace_back();
}

void Parameters::pop_scope() {
  if (scopes_.size() > 1) scopes_.pop_back();
}

void Parameters::check(int number, double value, int column) const {
  if (is_persistent_parameter(number) && !storable(value)) {
    throw Failure{
        out_of_range_message("Parameter #" + std::to_string(number), value), column, {}, 0};
  }
}

namespace {

// LinuxCNC's files hold about a hundred short lines: anything much larger is something else.
constexpr std::uintmax_t kMaxFileBytes = 1U << 20;

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

// A line as a message quotes it: printable characters only, cut at 60.
std::string quote_line(std::string_view line) {
  std::string out = "'";
  for (const char c : line.substr(0, 60))
    out.push_back(std::isprint(static_cast<unsigned char>(c)) ? c : '?');
  if (line.size() > 60) out += "...";
  return out + "'";
}

// Splits a line into exactly two blank-separated fields; false for any other shape.
bool split_pair(std::string_view line, std::string_view& first, std::string_view& second) {
  std::string_view fields[3];
  int count = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    if (is_blank(line[i])) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < line.size() && !is_blank(line[end]))
      ++end;
    if (count == 3) return false;
    fields[count++] = line.substr(i, end - i);
    i = end;
  }
  if (count != 2) return false;
  first = fields[0];
  second = fields[1];
  return true;
}

std::string_view without_plus(std::string_view field) {
  return field.size() > 1 && field.front() == '+' ? field.substr(1) : field;
}

enum class Parsed { ok, not_a_number, not_finite };

Parsed parse_value(std::string_view field, double& value) {
  field = without_plus(field);
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ptr != end || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    return Parsed::not_a_number;
  }
  if (ec == std::errc::result_out_of_range) {
    // Too large (infinite) or too small (a denormal or zero: harmless).
    value = std::strtod(std::string(field).c_str(), nullptr);
  }
  return std::isfinite(value) ? Parsed::ok : Parsed::not_finite;
}

}  // namespace

std::optional<std::string> Parameters::load(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return path.string() + ": is not a regular file, so not a parameter file";
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) return path.string() + ": " + error.message();
  if (size > kMaxFileBytes) {
    return path.string() + ": " + std::to_string(size) +
           " bytes is too large for a parameter file: is it one?";
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return "Unable to open parameter file: " + path.string();
  std::vector<double> loaded = numbered_;
  std::vector<int> first_line(kMaxParameter, 0);
  int previous = 0;
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    const std::string where = path.string() + ":" + std::to_string(line_number) + ": ";
    std::string_view number_field, value_field;
    if (!split_pair(text, number_field, value_field)) {
      bool blank = true;
      for (const char c : text)
        blank = blank && is_blank(c);
      if (blank) continue;
    }
    int number = 0;
    double value = 0;
    const auto field = without_plus(number_field);
    const char* field_end = field.data() + field.size();
    const auto read = std::from_chars(field.data(), field_end, number);
    const Parsed parsed = read.ec == std::errc() && read.ptr == field_end && !field.empty()
                              ? parse_value(value_field, value)
                              : Parsed::not_a_number;
    if (parsed == Parsed::not_a_number) {
      return where + quote_line(text) + " is not a parameter line (NUMBER VALUE)" +
             (previous == 0 ? ": is this a parameter file?" : "");
    }
    if (number < 1 || number >= kMaxParameter) {
      return where + "parameter number " + std::to_string(number) + " is out of range (1-" +
             std::to_string(kMaxParameter - 1) + ")";
    }
    const auto n = static_cast<std::size_t>(number);
    if (first_line[n] != 0) {
      return where + "parameter " + std::to_string(number) + " is given twice (first on line " +
             std::to_string(first_line[n]) + ")";
    }
    if (number < previous) {
      return where + "parameter " + std::to_string(number) + " comes after " +
             std::to_string(previous) + ": the numbers must increase";
    }
    const std::string value_text =
        "parameter " + std::to_string(number) + ": value '" + std::string(value_field) + "'";
    if (parsed == Parsed::not_finite) return where + value_text + " is not a finite number";
    if (!storable(value)) {
      return where + value_text + " is out of range (at most 1e9 in size)";
    }
    first_line[n] = line_number;
    previous = number;
    loaded[n] = value;
  }
  if (in.bad()) return "Unable to read parameter file: " + path.string();
  numbered_ = std::move(loaded);
  return std::nullopt;
}

std::optional<std::string> Parameters::save(const std::filesystem::path& path) const {
  // set() lets no such value in: this is the last line of defence for the file.
  for (int number = 1; number < kMaxParameter; ++number) {
    const double value = numbered_[static_cast<std::size_t>(number)];
    if (is_persistent_parameter(number) && !storable(value)) {
      return path.string() + ": not written: " +
             out_of_range_message("parameter #" + std::to_string(number), value);
    }
  }
  // A name of its own each time, created exclusively (mkstemp: O_CREAT | O_EXCL), so that a
  // link planted where the temporary goes is never followed.
  const auto dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string temp_name = (dir / ("." + path.filename().string() + ".XXXXXX")).string();
  errno = 0;
  const int fd = ::mkostemp(temp_name.data(), O_CLOEXEC);
  if (fd < 0) {
    return "Unable to write parameter file " + path.string() +
           ": cannot create a temporary file beside it: " + std::strerror(errno);
  }
  const std::filesystem::path temp = temp_name;
  // Whatever fails, the temporary file goes: a full disk must not be left fuller, nor a
  // truncated copy lie beside the file.
  const auto fail = [&](const std::string& what) {
    const std::string reason = std::strerror(errno);
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return what + ": " + reason;
  };
  std::FILE* out = ::fdopen(fd, "w");
  if (out == nullptr) {
    ::close(fd);
    return fail("Unable to write parameter file " + temp.string());
  }
  for (int number = 1; number < kMaxParameter; ++number) {
    if (!is_persistent_parameter(number)) continue;
    std::fprintf(out, "%d\t%f\n", number, numbered_[static_cast<std::size_t>(number)]);
  }
  // On disk before the rename, so that a crash leaves the old file or the new one.
  int error = 0;
  if (std::fflush(out) != 0 || std::ferror(out) != 0) {
    error = errno != 0 ? errno : EIO;
  } else if (::fchmod(fd, 0644) != 0 || ::fsync(fd) != 0) {
    error = errno;
  }
  if (std::fclose(out) != 0 && error == 0) error = errno;
  if (error != 0) {
    errno = error;
    return fail("Unable to write parameter file " + temp.string());
  }
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    return fail("Unable to replace parameter file " + path.string());
  }
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return std::nullopt;
}

}  // namespace cncd::interp
