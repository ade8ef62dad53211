// Names of enum values from a table in the enum's declaration order, the one way the project
// turns an enum into its protocol, report or file word.
#pragma once

#include <cstddef>

namespace cncd::config {

// The name of an enum value from a table in its declaration order; the first name for a value
// past the table's end.
template <typename Enum, std::size_t N>
const char* enum_name(Enum value, const char* const (&names)[N]) {
  const auto index = static_cast<std::size_t>(value);
  return index < N ? names[index] : names[0];
}

}  // namespace cncd::config
