// Lists of names in messages: "unknown model 'x' (known: a, b, c)".
#pragma once
#include <string>

namespace morphfem {

// The items of `items` with `sep` between them, each turned into text by `name`
// (e.g. join(registry, ", ", [](const auto& kv) { return kv.first; })).
template <class Range, class Name>
std::string join(const Range& items, const std::string& sep, Name name) {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) out += sep;
    out += name(item);
    first = false;
  }
  return out;
}

// A range of strings with `sep` between them: join(std::vector<std::string>{"a", "b"}, ", ") == "a, b".
template <class Range>
std::string join(const Range& items, const std::string& sep) {
  return join(
      items, sep, [](const auto& s) -> const auto& { return s; });
}

// The keys of a map (a registry by name) with `sep` between them, in the map's order.
template <class Map>
std::string join_keys(const Map& map, const std::string& sep) {
  return join(
      map, sep, [](const auto& kv) -> const auto& { return kv.first; });
}

}  // namespace morphfem
