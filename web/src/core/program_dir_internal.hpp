// Shared by program_dir.cpp and upload.cpp (not installed).
#pragma once

#include <time.h>

#include <chrono>
#include <string>
#include <string_view>

#include "cncd/web/program_dir.hpp"

namespace cncd::web {

// The start of the hidden names uploads are written under.
inline constexpr std::string_view kUploadPrefix = ".cncd-upload-";

std::string errno_text(int error);
std::chrono::system_clock::time_point to_time_point(const struct timespec& ts);
FileStatus fail(FileError error, std::string message);
// The status of check_program_name(name): bad_name with the reason, or ok.
FileStatus bad_name(std::string_view name);

}  // namespace cncd::web
