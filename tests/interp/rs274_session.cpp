#include "rs274_session.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <vector>

#include "cncd/config/ini_file.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp::testing {
namespace {

std::string quote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string run_command(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    output.append(buffer.data(), n);
  ::pclose(pipe);
  return output;
}

}  // namespace

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string line_diff(const std::string& expected_raw, const std::string& actual_raw) {
  // A center that LinuxCNC computes as a tiny negative number prints as -0.0000; ours is an
  // exact zero. The sign of a printed zero carries no meaning, so it is not compared.
  auto unsign_zeros = [](std::string text) {
    static const std::regex negative_zero(R"(-(0\.0+)(?![0-9]))");
    return std::regex_replace(text, negative_zero, "$1");
  };
  const std::string expected = unsign_zeros(expected_raw);
  const std::string actual = unsign_zeros(actual_raw);
  if (expected == actual) return {};
  auto split = [](const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
      lines.push_back(line);
    return lines;
  };
  const auto want = split(expected);
  const auto got = split(actual);
  std::size_t i = 0;
  while (i < want.size() && i < got.size() && want[i] == got[i])
    ++i;
  std::string out = "first difference at output line " + std::to_string(i + 1) + "\n";
  for (std::size_t k = i >= 3 ? i - 3 : 0; k < i; ++k)
    out += "    " + want[k] + "\n";
  for (std::size_t k = i; k < want.size() && k < i + 4; ++k)
    out += "  - " + want[k] + "\n";
  for (std::size_t k = i; k < got.size() && k < i + 4; ++k)
    out += "  + " + got[k] + "\n";
  return out;
}

SessionFiles files_next_to(const std::filesystem::path& program) {
  SessionFiles files;
  const auto dir = program.parent_path();
  if (std::filesystem::exists(dir / "tool.tbl")) {
    files.tool_table = dir / "tool.tbl";
  } else {
    files.tool_table = kRs274DefaultToolTable;
  }
  if (std::filesystem::exists(dir / "params.var")) files.parameter_file = dir / "params.var";
  if (std::filesystem::exists(dir / "machine.ini")) files.ini = dir / "machine.ini";
  return files;
}

SessionOutput run_ours(const std::filesystem::path& program, const SessionFiles& files) {
  InterpOptions options;
  options.tool_table = files.tool_table;
  options.tool_table_units = Units::inches;  // how rs274 reads tool tables
  if (!files.parameter_file.empty()) {
    // rs274 rewrites its parameter file; work on a copy like the differential test does.
    options.parameter_file = files.parameter_file;
  }
  if (!files.ini.empty()) {
    std::vector<config::Problem> problems, warnings;
    auto ini = std::make_shared<const config::IniFile>(
        config::IniFile::read(files.ini, problems, warnings));
    options.ini_value = [ini](const std::string& section, const std::string& key) {
      return ini->value(section, key);
    };
  }
  Interpreter interp(options);
  std::ostringstream out;
  Rs274Printer printer(out);
  SessionOutput result;
  auto error = interp.open(program);
  if (!error) error = run_program(interp, printer);
  // rs274 resets twice as it exits, once when it was given an INI.
  out << (files.ini.empty() ? "ON_RESET()\nON_RESET()\n" : "ON_RESET()\n");
  result.canon = out.str();
  if (error) result.error = error->message;
  return result;
}

std::optional<SessionOutput> run_rs274(const std::filesystem::path& program,
                                       const SessionFiles& files) {
  if (!std::filesystem::exists(kRs274)) return std::nullopt;
  const auto work =
      std::filesystem::temp_directory_path() / ("cncd-rs274-" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  std::string command = std::string(kRs274) + " -g";
  if (!files.tool_table.empty()) command += " -t " + quote(files.tool_table.string());
  if (!files.ini.empty()) command += " -i " + quote(files.ini.string());
  if (!files.parameter_file.empty()) {
    std::filesystem::copy_file(files.parameter_file, work / "params.var",
                               std::filesystem::copy_options::overwrite_existing);
    command += " -v " + quote((work / "params.var").string());
  }
  command += " " + quote(program.string());
  const auto errors_file = work / "stderr";
  // rs274 keeps its tool data in a memory-mapped file under $HOME; runs in parallel would
  // share (and truncate) it, so each run gets its own.
  const std::string canon_raw =
      run_command("cd " + quote(work.string()) + " && HOME=" + quote(work.string()) + " " +
                  command + " 2>" + quote(errors_file.string()));
  const std::string err_raw = read_file(errors_file);
  std::filesystem::remove_all(work);

  SessionOutput result;
  static const std::regex prefix(R"(^ *[0-9]+ N(\.\.\.\.\.|[0-9]+ *) )");
  std::istringstream lines(canon_raw);
  std::string line;
  while (std::getline(lines, line)) {
    std::smatch match;
    if (!std::regex_search(line, match, prefix)) continue;  // rs274's own chatter
    result.canon += line.substr(static_cast<std::size_t>(match.length(0))) + "\n";
  }
  std::istringstream errors(err_raw);
  std::getline(errors, line);  // "executing"
  if (std::getline(errors, line)) result.error = line;
  return result;
}

}  // namespace cncd::interp::testing
