#include "parameters.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

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
    throw Failure{out_of_range_message("Parameter #" + std::to_string(number), value), column};
  }
}

std::optional<std::string> Parameters::load(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return "Unable to open parameter file: " + path.string();
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    std::istringstream fields(text);
    int number = 0;
    double value = 0;
    if (!(fields >> number)) continue;  // LinuxCNC ignores lines that do not start with a number
    if (!(fields >> value)) {
      return path.string() + ":" + std::to_string(line_number) + ": parameter value missing";
    }
    if (number < 1 || number >= kMaxParameter) {
      return path.string() + ":" + std::to_string(line_number) + ": parameter number out of range";
    }
    numbered_[static_cast<std::size_t>(number)] = value;
  }
  return std::nullopt;
}

std::optional<std::string> Parameters::save(const std::filesystem::path& path) const {
  const std::filesystem::path temp = path.string() + ".tmp";
  // set() lets no such value in: this is the last line of defence for the file.
  for (int number = 1; number < kMaxParameter; ++number) {
    const double value = numbered_[static_cast<std::size_t>(number)];
    if (is_persistent_parameter(number) && !storable(value)) {
      return path.string() + ": not written: " +
             out_of_range_message("parameter #" + std::to_string(number), value);
    }
  }
  {
    std::FILE* out = std::fopen(temp.c_str(), "w");
    if (out == nullptr) return "Unable to write parameter file: " + temp.string();
    for (int number = 1; number < kMaxParameter; ++number) {
      if (!is_persistent_parameter(number)) continue;
      std::fprintf(out, "%d\t%f\n", number, numbered_[static_cast<std::size_t>(number)]);
    }
    // On disk before the rename, so that a crash leaves the old file or the new one.
    const bool ok = std::fflush(out) == 0 && ::fsync(::fileno(out)) == 0;
    std::fclose(out);
    if (!ok) return "Unable to write parameter file: " + temp.string();
  }
  std::error_code error;
  std::filesystem::rename(temp, path, error);
  if (error) return "Unable to replace parameter file: " + error.message();
  const auto dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return std::nullopt;
}

}  // namespace cncd::interp
