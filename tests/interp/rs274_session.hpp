// Runs a program the way LinuxCNC's `rs274 -g` does and returns what it would print: the
// canonical commands in rs274's format, then the two ON_RESET() rs274 prints when it exits,
// plus the error message if the program failed. Also runs the real rs274 when installed.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace cncd::interp::testing {

struct SessionOutput {
  std::string canon;  // one command per line
  std::string error;  // empty when the program ran to its end
};

struct SessionFiles {
  std::filesystem::path tool_table;      // empty = none
  std::filesystem::path parameter_file;  // empty = none
  std::filesystem::path ini;             // machine.ini, for #<_ini[...]>; empty = none
};

// A copy of the table rs274 reads when given none (LinuxCNC's sample-configs/common/tool.tbl),
// committed so that the goldens made with it need no LinuxCNC installed. Both interpreters are
// handed this file, never LinuxCNC's.
inline constexpr const char* kRs274DefaultToolTable = CNCD_RS274_DEFAULT_TOOL_TABLE;

// Looks for tool.tbl, params.var and machine.ini next to the program; without tool.tbl,
// rs274's default.
SessionFiles files_next_to(const std::filesystem::path& program);

SessionOutput run_ours(const std::filesystem::path& program, const SessionFiles& files);

inline constexpr const char* kRs274 = "/usr/bin/rs274";
// Runs the real rs274 in batch mode; nullopt when it is not installed.
std::optional<SessionOutput> run_rs274(const std::filesystem::path& program,
                                       const SessionFiles& files);

std::string read_file(const std::filesystem::path& path);

// Empty when equal, else the first differing line with a little context.
std::string line_diff(const std::string& expected, const std::string& actual);

}  // namespace cncd::interp::testing
