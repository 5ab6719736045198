// One name table per enum, used for parsing, printing and the lists in error messages.
//
// An enum E gets its names by a function found by argument-dependent lookup in E's namespace:
//   constexpr NameTable<E, N> kFooNames = {{{Foo::A, "a"}, {Foo::B, "b"}}};
//   constexpr const NameTable<E, N>& nameTable(Foo) { return kFooNames; }
// The table's order is the order of every list printed from it (nameList, nameVector and their -If forms),
// so the order of the choices in each message is the table's; names are exact, case-sensitive words.
#pragma once
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pvrr {

template <class E>
struct NamedValue {
  E value;
  const char* name;
};

template <class E, size_t N>
using NameTable = std::array<NamedValue<E>, N>;

// True when no two entries share a value or a name (for a static_assert beside each table).
template <class E, size_t N>
constexpr bool namesAreUnique(const NameTable<E, N>& table) {
  for (size_t i = 0; i < N; ++i)
    for (size_t j = i + 1; j < N; ++j) {
      if (table[i].value == table[j].value) return false;
      if (std::string_view(table[i].name) == std::string_view(table[j].name)) return false;
    }
  return true;
}

// The name of `value`; "?" for a value its table lacks.
template <class E>
constexpr const char* nameOf(E value) {
  for (const auto& entry : nameTable(E{}))
    if (entry.value == value) return entry.name;
  return "?";
}

// The value named exactly `text`, or nothing.
template <class E>
std::optional<E> parseName(std::string_view text) {
  for (const auto& entry : nameTable(E{}))
    if (text == entry.name) return entry.value;
  return std::nullopt;
}

// The names in table order, those `keep` accepts (all by default).
template <class E, class Keep>
std::vector<std::string> nameVectorIf(Keep keep) {
  std::vector<std::string> out;
  for (const auto& entry : nameTable(E{}))
    if (keep(entry.value)) out.emplace_back(entry.name);
  return out;
}
template <class E>
std::vector<std::string> nameVector() {
  return nameVectorIf<E>([](E) { return true; });
}

// The names in table order joined by `separator`, e.g. "pvrr, raster, raytrace, envmap, impostor".
template <class E, class Keep>
std::string nameListIf(Keep keep, const char* separator = ", ") {
  std::string out;
  for (const std::string& name : nameVectorIf<E>(keep)) out += (out.empty() ? "" : separator) + name;
  return out;
}
template <class E>
std::string nameList(const char* separator = ", ") {
  return nameListIf<E>([](E) { return true; }, separator);
}

}  // namespace pvrr
