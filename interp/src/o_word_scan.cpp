// Finding O-words in lines that are skipped or searched (the rest of an if, a loop that ends,
// a sub's body, the way to a sub defined further down) and in the program's index. rs274
// evaluates an O-word name that is a parameter or an expression even there: `o#1 endsub` in a
// sub's body ends the definition when #1 is its number.
#include <algorithm>
#include <cctype>
#include <limits>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

OScan scan_o_word(const std::string& line, std::string& name, OKind& kind) {
  std::size_t i = 0;
  auto skip_blanks = [&] {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
      ++i;
  };
  auto lower = [&](std::size_t k) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(line[k])));
  };
  auto is_digit = [&](std::size_t k) {
    return k < line.size() && std::isdigit(static_cast<unsigned char>(line[k]));
  };
  skip_blanks();
  if (i < line.size() && line[i] == '/') ++i;
  skip_blanks();
  if (i < line.size() && lower(i) == 'n') {
    ++i;
    while (i < line.size() && (is_digit(i) || line[i] == ' ' || line[i] == '.'))
      ++i;
  }
  skip_blanks();
  if (i >= line.size() || lower(i) != 'o') return OScan::none;
  ++i;
  name.clear();
  kind = OKind::none;
  skip_blanks();
  if (i < line.size() && (line[i] == '#' || line[i] == '[')) return OScan::computed;
  if (i < line.size() && line[i] == '<') {
    ++i;
    while (i < line.size() && line[i] != '>') {
      if (line[i] != ' ' && line[i] != '\t') name.push_back(lower(i));
      ++i;
    }
    ++i;
  } else {
    bool zero = false;
    while (is_digit(i) || (i < line.size() && line[i] == ' ')) {
      // Leading zeros are no part of the number: o0100 is o100.
      zero = zero || line[i] == '0';
      if (line[i] != ' ' && (line[i] != '0' || !name.empty())) name.push_back(line[i]);
      ++i;
    }
    if (name.empty() && zero) name = "0";
  }
  std::string word;
  skip_blanks();
  while (i < line.size() && std::isalpha(static_cast<unsigned char>(line[i])))
    word += lower(i++);
  if (word.empty()) return name.empty() ? OScan::none : OScan::o_word;
  // As rs274 reads a line it skips: "endiffy" is endif; "foo" is an error there.
  std::size_t matched = 0;
  kind = match_o_keyword(word, matched);
  return kind == OKind::none ? OScan::unknown : OScan::o_word;
}

bool Interpreter::Impl::scan_o_line(const std::string& line, std::string& name, OKind& kind) {
  const OScan found = scan_o_word(line, name, kind);
  if (found == OScan::none) return false;
  if (found == OScan::o_word) return true;
  try {
    if (found == OScan::unknown) fail("Unknown control command in o word");
    parser_.set_dialect(dialect_);
    return parser_.read_o_head(line, name, kind);
  } catch (Failure& failure) {
    // A line read while seeking a sub is not the current one: name it.
    if (failure.line == 0) {
      failure.file = source().name();
      failure.line = source().line_number();
    }
    throw;
  }
}

// The first definition of `name` at or after `offset` in the indexed program file: seeks
// there, checks it is still the sub's line and registers it. The lines with a computed O-word
// name on the way are evaluated in order, as a search that reads every line would.
bool Interpreter::Impl::find_indexed_sub(const std::string& name, std::int64_t offset,
                                         int& closing_line) {
  using Definition = SubroutineIndex::Definition;
  auto before = [](const Definition& d, std::int64_t at) { return d.offset < at; };
  const Definition* fixed = nullptr;
  if (const auto found = sub_index_->definitions.find(name);
      found != sub_index_->definitions.end()) {
    const auto& all = found->second;
    const auto def = std::lower_bound(all.begin(), all.end(), offset, before);
    if (def != all.end()) fixed = &*def;
  }
  const int line_number = source().line_number();
  auto changed = [&](int line) {
    source().seek(offset, line_number);
    fail(source().name() + " has changed since it was opened (" + o_label(name) +
         " sub is no longer at line " + std::to_string(line) + "): open it again");
  };
  auto register_here = [&] {
    subs_[name] = SubInfo{sources_.size() - 1, source().tell(), source().line_number(), true};
    source().seek(offset, line_number);
    return true;
  };
  const auto& computed = sub_index_->computed;
  std::int64_t limit = fixed ? fixed->offset : std::numeric_limits<std::int64_t>::max();
  const Definition& closing = sub_index_->closing_percent;
  const bool before_end = seen_percent_ && closing.offset >= 0 && offset <= closing.offset;
  if (before_end && closing.offset < limit) {
    limit = closing.offset;
    fixed = nullptr;
  }
  for (auto it = std::lower_bound(computed.begin(), computed.end(), offset, before);
       it != computed.end() && it->offset < limit; ++it) {
    source().seek(it->offset, it->line - 1);
    OKind kind = OKind::none;
    if (!source().read_line(line_) || scan_o_word(line_, o_scan_name_, kind) != OScan::computed) {
      changed(it->line);
    }
    if (scan_o_line(line_, o_scan_name_, kind) && kind == OKind::sub && o_scan_name_ == name)
      return register_here();
  }
  if (fixed == nullptr) {
    if (before_end) closing_line = closing.line;
    source().seek(offset, line_number);
    return false;
  }
  source().seek(fixed->offset, fixed->line - 1);
  OKind kind = OKind::none;
  const bool there = source().read_line(line_) &&
                     scan_o_word(line_, o_scan_name_, kind) == OScan::o_word &&
                     kind == OKind::sub && o_scan_name_ == name;
  if (!there) changed(fixed->line);
  return register_here();
}

std::optional<InterpError> index_program(const std::filesystem::path& program, SubroutineIndex& out,
                                         const std::function<bool()>& cancelled) {
  out = SubroutineIndex{};
  LineSource source;
  if (const std::string why = source.open_file(program); !why.empty())
    return InterpError{program.string(), 0, 0, "Unable to open file: " + why};
  std::string line;
  std::string name;
  std::size_t count = 0;
  bool text_seen = false;
  bool opened = false;
  try {
    for (;;) {
      const std::int64_t offset = source.tell();
      if (!source.read_line(line)) break;
      if ((source.line_number() & 4095) == 0 && cancelled && cancelled())
        return InterpError{program.string(), 0, 0, "reading the program was cancelled"};
      if (out.closing_percent.offset >= 0) continue;  // past the program's end: lines only
      if (is_percent_line(line)) {
        if (opened) out.closing_percent = {offset, source.line_number()};
        opened = opened || !text_seen;
        text_seen = true;
        continue;
      }
      text_seen = text_seen || line.find_first_not_of(" \t\r") != std::string::npos;
      OKind kind = OKind::none;
      const OScan found = scan_o_word(line, name, kind);
      const bool computed = found == OScan::computed;
      if (!computed && (found != OScan::o_word || kind != OKind::sub)) continue;
      if (++count > SubroutineIndex::kMaxDefinitions) {
        return InterpError{program.string(), source.line_number(), 0,
                           "more than " + std::to_string(SubroutineIndex::kMaxDefinitions) +
                               " subroutine definitions"};
      }
      SubroutineIndex::Definition here{offset, source.line_number()};
      if (computed) {
        out.computed.push_back(here);
      } else {
        out.definitions[name].push_back(here);
      }
    }
  } catch (const Failure& failure) {
    return InterpError{failure.file, failure.line, 0, failure.message};
  }
  out.lines = static_cast<std::uint64_t>(source.line_number());
  return std::nullopt;
}

}  // namespace cncd::interp
