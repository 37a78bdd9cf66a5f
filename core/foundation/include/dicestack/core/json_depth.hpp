#pragma once
// JSON read with a nesting limit. nlohmann's parser is iterative, but destroying or printing a
// value is recursive: a file nested 200,000 levels deep crashed dicestack. Every reader of a
// JSON file goes through here. Header-only and independent of the JSON library's headers, so
// that core's public interface does not depend on nlohmann: instantiate it with nlohmann::json.
#include <string>
#include <string_view>

#include <dicestack/core/error.hpp>

namespace dicestack {

/// Deepest nesting any dicestack file has (a model header: 3) with a wide margin.
inline constexpr int kMaxJsonDepth = 64;

/// Parses `text` (a string or stream, as Json::parse takes) into a Json value; throws InputError
/// "WHERE: JSON nested deeper than 64 levels" past the limit, and lets the library's own parse
/// errors through (callers add their context).
template <class Json, class Text>
Json parse_json_limited(Text&& text, std::string_view where) {
  typename Json::parser_callback_t guard = [&](int depth, typename Json::parse_event_t, Json&) {
    if (depth > kMaxJsonDepth)
      throw InputError(std::string(where) + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return true;
  };
  return Json::parse(std::forward<Text>(text), guard);
}

}  // namespace dicestack
