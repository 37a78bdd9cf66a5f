#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

// The message parse_json_limited gives for `text` read from the file `where`, or "" if it parses.
std::string refusal(const std::string& text, const std::string& where) {
  return test::error_of([&] { parse_json_limited<nlohmann::json>(text, where); });
}

TEST(JsonInput, ARepeatedKeyIsRefusedAtAnyDepthNamingItsFileAndTheKey) {
  EXPECT_EQ(refusal(R"({"gravity": 0.1, "gravity": 0.4})", "p.json"), "p.json: key \"gravity\" appears twice in one object");
  EXPECT_EQ(refusal(R"({"a": [{"b": 1, "c": {"d": 1, "d": 2}}]})", "w.json"), "w.json: key \"d\" appears twice in one object");
  EXPECT_THROW(parse_json_limited<nlohmann::ordered_json>(std::string(R"({"x": 1, "x": 1})"), "o.json"), InputError);
  const std::string key(5000, 'k');  // not echoed whole
  EXPECT_LT(refusal("{\"" + key + "\": 1, \"" + key + "\": 2}", "l.json").size(), 120u);
}

TEST(JsonInput, TheSameKeyInDifferentObjectsIsFine) {
  EXPECT_EQ(refusal(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 3}, {"x": 4}], "x": 5})", "f"), "");
  const auto j = parse_json_limited<nlohmann::json>(std::string(R"({"c": [{"x": 3}, {"x": 4}], "x": 5})"), "f");
  EXPECT_EQ(j["c"][1]["x"], 4);
  EXPECT_EQ(j["x"], 5);
}

}  // namespace
}  // namespace dicestack
