// Numbered and named parameters (#1..#5601, #<local>, #<_global>) with LinuxCNC's scoping:
// names without a leading underscore are local to the current subroutine call.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace cncd::interp {

inline constexpr int kMaxParameter = 5602;  // valid numbers are 1..5601

// LinuxCNC's persistent parameters: the ones it saves to and loads from the .var file.
bool is_persistent_parameter(int number);

class Parameters {
 public:
  Parameters();

  double get(int number) const { return numbered_[static_cast<std::size_t>(number)]; }
  // Every numbered parameter is assigned here, so the persistent ones (offsets, origins,
  // G28/G30 points) can only ever hold storable values (stored_values.hpp): for anything else
  // this throws Failure (at `column` of the line) and changes nothing. check() is the same
  // test without the assignment, for a block that sets several: all or none.
  void set(int number, double value, int column = 0) {
    check(number, value, column);
    numbered_[static_cast<std::size_t>(number)] = value;
  }
  void check(int number, double value, int column = 0) const;

  // Under cutter compensation the position parameters #5420-#5428 may not be read (the
  // position is still to be decided by the next move), as in LinuxCNC.
  void hide_position(bool hidden) { position_hidden_ = hidden; }
  bool position_hidden() const { return position_hidden_; }

  // Named parameters. Read-only predefined names (_x, _metric ...) come from `predefined_`.
  std::optional<double> get_named(std::string_view name) const;
  bool exists_named(std::string_view name) const;
  void set_named(std::string_view name, double value);

  // Subroutine scopes: locals of the callee are invisible to the caller.
  void push_scope();
  void pop_scope();
  std::size_t depth() const { return scopes_.size(); }

  using Predefined = std::function<std::optional<double>(std::string_view)>;
  void set_predefined(Predefined lookup) { predefined_ = std::move(lookup); }

  // Reads a LinuxCNC .var file: "NUMBER VALUE" a line (blanks between and around), numbers
  // increasing, values storable; blank lines are allowed. Anything else (a line that is not
  // such a pair, a repeated number, a value that is not storable) is refused with
  // "FILE:LINE: what is wrong" and nothing is loaded.
  std::optional<std::string> load(const std::filesystem::path& path);
  // Writes the persistent parameters: temp file, flush, rename, so a crash never loses them.
  std::optional<std::string> save(const std::filesystem::path& path) const;

 private:
  using Scope = std::unordered_map<std::string, double>;
  std::vector<double> numbered_;
  Scope globals_;
  std::vector<Scope> scopes_;  // back() = current subroutine's locals; front() = main program
  Predefined predefined_;
  bool position_hidden_ = false;
};

}  // namespace cncd::interp
