#include "cncd/config/machine_config.hpp"

#include <algorithm>
#include <cctype>
#include <exception>
#include <map>
#include <new>
#include <ostream>

#include "cncd/config/ini_file.hpp"
#include "loader.hpp"

namespace cncd::config {

int axis_index(char letter) {
  const auto upper = static_cast<char>(std::toupper(static_cast<unsigned char>(letter)));
  const std::size_t at = upper == '\0' ? std::string_view::npos : kAxisLetters.find(upper);
  return at == std::string_view::npos ? -1 : static_cast<int>(at);
}

std::string Problem::to_string() const {
  std::string out = file.empty() ? std::string("<config>") : file;
  if (line > 0) out += ":" + std::to_string(line);
  out += ": ";
  if (!section.empty()) out += "[" + section + "] ";
  if (!key.empty()) out += key + ": ";
  return out + message;
}

namespace {

// Files in the order they first appear, lines ascending within a file.
void sort_by_place(std::vector<Problem>& problems) {
  std::map<std::string, std::size_t, std::less<>> rank;
  for (const auto& p : problems)
    rank.emplace(p.file, rank.size());
  std::stable_sort(problems.begin(), problems.end(), [&](const Problem& a, const Problem& b) {
    const auto ra = rank[a.file];
    const auto rb = rank[b.file];
    return ra != rb ? ra < rb : a.line < b.line;
  });
}

LoadResult load(const std::filesystem::path& ini_path, const LoadOptions& options) {
  LoadResult result;
  auto ini = std::make_shared<IniFile>(IniFile::read(ini_path, result.problems, result.warnings));
  if (ini->sections().empty() && ini->entries().empty()) {
    // Nothing to interpret (a missing file, binary junk, an empty file): listing every
    // missing key on top would bury the one problem that matters.
    if (result.problems.empty()) {
      result.problems.push_back(Problem{ini_path.lexically_normal().string(), 0, "", "",
                                        "no sections; is this an INI file?"});
    }
    return result;
  }
  TypedReader reader(*ini, result.problems, result.warnings);
  MachineConfig config;
  config.path = ini_path;
  load_general(reader, config);
  load_program_dirs(reader, config, options);
  load_state_files(reader, config, options);
  load_web(reader, config);
  load_telemetry(reader, config);
  load_spindle(reader, config);
  load_io(reader, config);
  load_panel(reader, config);
  if (check_sections(reader)) {
    load_motion(reader, config);
    validate(reader, config);
    validate_io(reader, config);
  }
  check_keys(reader);
  config.ini = std::move(ini);
  sort_by_place(result.problems);
  sort_by_place(result.warnings);
  if (result.problems.empty()) result.config = std::move(config);
  return result;
}

}  // namespace

std::optional<MachineConfig> load_or_report(const std::filesystem::path& ini_path,
                                            std::string_view program, std::ostream& err) {
  auto loaded = load_machine_config(ini_path);
  if (loaded.ok()) return std::move(loaded.config);
  for (const auto& problem : loaded.problems)
    err << problem.to_string() << '\n';
  err << program << ": " << loaded.problems.size() << " problem"
      << (loaded.problems.size() == 1 ? "" : "s") << " in " << ini_path.string() << '\n';
  return std::nullopt;
}

LoadResult load_machine_config(const std::filesystem::path& ini_path, const LoadOptions& options) {
  // Bad input never throws here; what remains is running out of memory or a filesystem
  // error, which must still reach the operator as a problem rather than terminate the daemon.
  try {
    return load(ini_path, options);
  } catch (const std::exception& e) {
    LoadResult failed;
    failed.problems.push_back(
        Problem{ini_path.string(), 0, "", "", std::string("cannot load: ") + e.what()});
    return failed;
  }
}

}  // namespace cncd::config
