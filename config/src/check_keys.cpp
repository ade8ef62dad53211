// Keys written twice, and keys that look like a misspelt known key. LinuxCNC keeps every line
// of a repeated key and most programs read the first; for the keys cncd interprets (all of
// them single-valued) a second line is either dead or a forgotten edit. Keys cncd does not
// know are legitimate in LinuxCNC (HAL files read any [SECTION]KEY), so only one within a
// typo of a known key is reported.
#include <algorithm>
#include <string>
#include <vector>

#include "key_makers.hpp"
#include "linuxcnc_keys.hpp"
#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

// Edits (insert, delete, replace, swap of neighbours) from `a` to `b`.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i)
    d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j)
    d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// Short keys are too close to each other for a guess to mean anything.
std::size_t allowed_edits(std::string_view key) {
  if (key.size() >= 8) return 2;
  return key.size() >= 4 ? 1 : 0;
}

// The known keys of a section; an axis key ("JOG_L_PLUS") is guessed with the axis letter the
// typed key has in its place ("JOG_Y_PLSU" -> JOG_Y_PLUS).
std::vector<std::string> known_keys(std::string_view pattern, std::string_view typed) {
  std::vector<std::string> keys;
  for (const auto& spec : key_table()) {
    if (spec.section != pattern) continue;
    std::string key(spec.key);
    const std::size_t at = key_makers::axis_placeholder(key);
    if (at < typed.size() && kAxisLetters.find(typed[at]) != std::string_view::npos) {
      key[at] = typed[at];
    }
    keys.push_back(std::move(key));
  }
  for (const auto key : linuxcnc_keys(pattern))
    keys.emplace_back(key);
  return keys;
}

// "line 12", or "FILE:12" when `where` is in another file than `from` (an #INCLUDE).
std::string at(const SourceRef& where, const SourceRef& from) {
  const std::string line = std::to_string(where.line);
  return where.file == from.file ? "line " + line : where.file + ":" + line;
}

// MIN_ and MAX_ keys are pairs, not typos of each other.
bool min_max_pair(std::string_view a, std::string_view b) {
  return a.size() == b.size() && a.size() > 4 && a.substr(4) == b.substr(4) &&
         ((a.starts_with("MIN_") && b.starts_with("MAX_")) ||
          (a.starts_with("MAX_") && b.starts_with("MIN_")));
}

void check_repeated(TypedReader& r, const IniEntry& entry) {
  const IniEntry* first = r.ini().find(entry.section, entry.key);
  if (first == nullptr || first == &entry) return;
  const std::string message =
      first->value == entry.value
          ? "given again; the first, at " + at(first->source, entry.source) + ", has the same value"
          : "given again with another value (" + printable(entry.value) +
                "), which is ignored: the first, at " + at(first->source, entry.source) + " (" +
                printable(first->value) + "), is used";
  r.warnings().push_back(
      Problem{entry.source.file, entry.source.line, entry.section, entry.key, message});
}

}  // namespace

std::string did_you_mean(std::string_view section, std::string_view key) {
  const std::string_view pattern = key_table_section(section);
  if (pattern.empty()) return "";
  const std::string upper = to_upper(key);
  const auto keys = known_keys(pattern, upper);
  for (const auto& known : keys) {
    if (iequals(known, key)) {
      return "; did you mean " + known + "? (key names are case-sensitive)";
    }
  }
  std::string_view best;
  std::size_t best_edits = allowed_edits(key) + 1;
  for (const auto& known : keys) {
    const std::size_t edits = edit_distance(upper, known);
    if (edits < best_edits && !min_max_pair(upper, known)) {
      best = known;
      best_edits = edits;
    }
  }
  return best.empty() ? "" : "; did you mean " + std::string(best) + "?";
}

void refuse_unknown_keys(TypedReader& r, std::string_view section, std::string_view whose) {
  for (const auto& entry : r.ini().entries()) {
    if (entry.section == section && entry.section_occurrence == 0 &&
        find_key_spec(section, entry.key) == nullptr) {
      r.problem(section, entry.key,
                "unknown key in " + std::string(whose) + did_you_mean(section, entry.key));
    }
  }
}

void check_keys(TypedReader& r) {
  for (const auto& entry : r.ini().entries()) {
    if (entry.section_occurrence != 0) continue;
    const std::string_view pattern = key_table_section(entry.section);
    if (pattern.empty()) continue;
    if (find_key_spec(entry.section, entry.key) != nullptr) {
      check_repeated(r, entry);
      continue;
    }
    // [CNCD], [WEB], [PANEL] and [TELEMETRY] are cncd's own: an unknown key there is a
    // problem (load_general, load_web, load_panel, load_telemetry).
    if (pattern == "CNCD" || pattern == "WEB" || pattern == "PANEL" || pattern == "TELEMETRY")
      continue;
    const auto linuxcnc = linuxcnc_keys(pattern);
    if (std::find(linuxcnc.begin(), linuxcnc.end(), entry.key) != linuxcnc.end()) continue;
    if (const std::string guess = did_you_mean(entry.section, entry.key); !guess.empty()) {
      r.warnings().push_back(Problem{entry.source.file, entry.source.line, entry.section, entry.key,
                                     "unknown key, ignored" + guess});
    }
  }
}

}  // namespace cncd::config
