#pragma once
// JSON read with a nesting limit and unique keys. nlohmann's parser is iterative, but destroying
// or printing a value is recursive: a file nested 200,000 levels deep crashed dicestack. And it
// keeps the last of two equal keys, so a settings file naming `gravity` twice would run with one
// of them silently. Every reader of a JSON file goes through here. Header-only and independent
// of the JSON library's headers, so that core's public interface does not depend on nlohmann:
// instantiate it with nlohmann::json.
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/error.hpp>

namespace dicestack {

/// Deepest nesting any dicestack file has (a model header: 3) with a wide margin.
inline constexpr int kMaxJsonDepth = 64;

/// Parses `text` (a string or stream, as Json::parse takes) into a Json value; throws InputError
/// "WHERE: JSON nested deeper than 64 levels" past the limit, "WHERE: key "K" appears twice in
/// one object" for a repeated key, and lets the library's own parse errors through (callers add
/// their context).
template <class Json, class Text>
Json parse_json_limited(Text&& text, std::string_view where) {
  using Event = typename Json::parse_event_t;
  std::vector<std::set<std::string>> keys;  // the keys of each object being read, innermost last
  typename Json::parser_callback_t guard = [&](int depth, Event event, Json& parsed) {
    if (depth > kMaxJsonDepth)
      throw InputError(std::string(where) + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    if (event == Event::object_start) keys.emplace_back();
    if (event == Event::object_end && !keys.empty()) keys.pop_back();
    if (event == Event::key && !keys.empty() && parsed.is_string()) {
      const auto& key = parsed.template get_ref<const typename Json::string_t&>();
      if (!keys.back().insert(key).second)
        throw InputError(std::string(where) + ": key \"" + (key.size() > 40 ? key.substr(0, 40) + "..." : key) +
                         "\" appears twice in one object");
    }
    return true;
  };
  return Json::parse(std::forward<Text>(text), guard);
}

}  // namespace dicestack
