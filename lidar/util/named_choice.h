// Closed choices named in text (options, files, reports): one table of (name, value) per enum, and
// the one parser and printer over such tables, e.g.
//   inline constexpr NamedChoices<ImageMatcher, 3> kImageMatcherNames = {{
//       {"exhaustive", ImageMatcher::kExhaustive}, ...}};
//   ImageMatcher matcher = ChoiceFromName(kImageMatcherNames, "spatial", "matcher");
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace colmap_lidar {

template <typename Enum>
struct NamedChoice {
  const char* name;
  Enum value;
};
template <typename Enum, size_t N>
using NamedChoices = std::array<NamedChoice<Enum>, N>;

// "a, b or c": the names of a table, for help texts and errors.
template <typename Enum, size_t N>
std::string ChoiceNames(const NamedChoices<Enum, N>& table) {
  std::string names;
  for (size_t i = 0; i < N; ++i) {
    if (i > 0) names += i + 1 == N ? " or " : ", ";
    names += table[i].name;
  }
  return names;
}

// The value named `name`; throws std::invalid_argument naming `what` and the choices.
template <typename Enum, size_t N>
Enum ChoiceFromName(const NamedChoices<Enum, N>& table,
                    const std::string& name,
                    const std::string& what) {
  for (const NamedChoice<Enum>& choice : table) {
    if (name == choice.name) return choice.value;
  }
  throw std::invalid_argument("unknown " + what + " '" + name + "' (expected " +
                              ChoiceNames(table) + ")");
}

// The first name of `value` in the table; throws std::logic_error if the table lacks it.
template <typename Enum, size_t N>
const char* ChoiceName(const NamedChoices<Enum, N>& table, Enum value) {
  for (const NamedChoice<Enum>& choice : table) {
    if (choice.value == value) return choice.name;
  }
  throw std::logic_error("a choice without a name");
}

}  // namespace colmap_lidar
