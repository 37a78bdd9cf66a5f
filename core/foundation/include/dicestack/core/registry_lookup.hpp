#pragma once
// Name lookups shared by dicestack's registries (regressors, learners): a registry is a map from
// the command-line name to its entry, and an unknown name is an error that lists the known ones
// (STYLE 5).
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/error.hpp>

namespace dicestack {

/// The names in a registry's map, in order.
template <class Map>
std::vector<std::string> registered_names(const Map& entries) {
  std::vector<std::string> out;
  for (const auto& entry : entries) out.push_back(entry.first);
  return out;
}

/// A registry's entry by name; throws ConfigError naming the `kind` ("regressor", "learner"),
/// the unknown name and every registered one. Shared by the regressor and learner registries.
template <class Map>
const typename Map::mapped_type& registered_entry(const Map& entries, std::string_view name, std::string_view kind) {
  const auto it = entries.find(name);
  if (it == entries.end()) {
    std::string list;
    for (const auto& n : registered_names(entries)) list += (list.empty() ? "" : ", ") + n;
    throw ConfigError("unknown " + std::string(kind) + " \"" + std::string(name) + "\"; registered: " + list);
  }
  return it->second;
}

}  // namespace dicestack
