// Where the files cncd rewrites while it runs (parameters, tools, joint positions) live: in a
// state directory, never beside the INI, so that a machine's configuration (a checkout, a
// package's /usr/share) stays as it was shipped.
#include <string>

#include "loader.hpp"

namespace cncd::config {
namespace {

struct Choice {
  std::filesystem::path dir;
  std::string origin;
};

Choice choose_state_dir(TypedReader& r, const MachineConfig& c, const LoadOptions& options) {
  if (!options.state_dir.empty()) {
    return {std::filesystem::absolute(options.state_dir).lexically_normal(), "--state-dir"};
  }
  if (const auto dir = r.path("CNCD", "STATE_DIR"); dir && !dir->empty()) {
    return {std::filesystem::absolute(*dir).lexically_normal(), "[CNCD] STATE_DIR"};
  }
  auto env = [&](const char* name) -> std::string {
    const char* value = options.getenv != nullptr ? options.getenv(name) : nullptr;
    return value != nullptr ? value : "";
  };
  // systemd's StateDirectory= may list several, colon-separated; the first is the unit's own.
  if (std::string dirs = env("STATE_DIRECTORY"); !dirs.empty()) {
    dirs = dirs.substr(0, dirs.find(':'));
    if (std::filesystem::path(dirs).is_absolute()) return {dirs, "$STATE_DIRECTORY"};
  }
  const std::string machine = c.path.stem().string();
  if (const std::string xdg = env("XDG_STATE_HOME"); std::filesystem::path(xdg).is_absolute()) {
    return {std::filesystem::path(xdg) / "cncd" / machine, "$XDG_STATE_HOME/cncd/" + machine};
  }
  if (const std::string home = env("HOME"); std::filesystem::path(home).is_absolute()) {
    return {std::filesystem::path(home) / ".local/state/cncd" / machine,
            "$HOME/.local/state/cncd/" + machine};
  }
  return {};
}

void place(TypedReader& r, const MachineConfig& c, std::string_view section, std::string_view key,
           std::filesystem::path& file, std::filesystem::path& seed) {
  const auto text = r.text(section, key);
  if (!text || text->empty()) return;
  const std::filesystem::path given(*text);
  if (given.is_absolute()) {
    file = given.lexically_normal();
    return;
  }
  if (c.cncd.state_dir.empty()) {
    r.problem(section, key,
              "a relative path needs a state directory: set [CNCD] STATE_DIR (none of "
              "$STATE_DIRECTORY, $XDG_STATE_HOME and $HOME is set)");
    return;
  }
  file = (c.cncd.state_dir / given).lexically_normal();
  seed = (r.ini().directory() / given).lexically_normal();
}

}  // namespace

void load_state_files(TypedReader& r, MachineConfig& c, const LoadOptions& options) {
  const Choice choice = choose_state_dir(r, c, options);
  c.cncd.state_dir = choice.dir;
  c.cncd.state_dir_origin = choice.origin;
  place(r, c, "RS274NGC", "PARAMETER_FILE", c.parameter_file, c.parameter_file_seed);
  place(r, c, "EMCIO", "TOOL_TABLE", c.tool_table, c.tool_table_seed);
  place(r, c, "TRAJ", "POSITION_FILE", c.position_file, c.position_file_seed);
  const auto probe = r.text("CNCD", "PROBE_DIR");
  const std::filesystem::path given = probe ? *probe : std::string();
  if (given.is_absolute()) {
    c.cncd.probe_dir = given.lexically_normal();
  } else if (!c.cncd.state_dir.empty()) {
    c.cncd.probe_dir = (c.cncd.state_dir / (given.empty() ? "probe" : given)).lexically_normal();
  }
}

std::filesystem::path state_file_to_read(const std::filesystem::path& file,
                                         const std::filesystem::path& seed) {
  std::error_code ec;
  if (file.empty() || std::filesystem::exists(file, ec) || seed.empty()) return file;
  return std::filesystem::exists(seed, ec) ? seed : file;
}

}  // namespace cncd::config
