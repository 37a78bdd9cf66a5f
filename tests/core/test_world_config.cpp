#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/world_config.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using test::error_of;

nlohmann::json default_json() { return nlohmann::json::parse(to_json(WorldConfig{})); }

std::string error_for(const nlohmann::json& j) {
  return error_of([&] { world_config_from_json(j.dump(), "w.json"); });
}

TEST(WorldConfig, DefaultsAreThePapersAndValid) {
  const WorldConfig c;
  EXPECT_NO_THROW(validate(c));
  EXPECT_DOUBLE_EQ(c.physics.gravity.y, -4.0);
  EXPECT_EQ(c.physics.substeps, 5);
  EXPECT_EQ(c.physics.velocity_iterations, 10);
  EXPECT_DOUBLE_EQ(c.physics.control_dt, 1.0 / 30.0);
  EXPECT_DOUBLE_EQ(c.dice.friction, 0.6);
  EXPECT_DOUBLE_EQ(c.cup.friction, 0.4);
  EXPECT_DOUBLE_EQ(c.walls.friction, 1.0);
  EXPECT_DOUBLE_EQ(c.walls.floor_y + c.walls.radius, 1.0);
}

TEST(WorldConfig, JsonRoundTripKeepsEveryField) {
  WorldConfig c;
  c.physics.substeps = 7;
  c.cup.start_anchor = {3.5, 2.0};
  c.dice.start_x = {4.0, 4.5, 5.0};
  c.randomization.die_quarter_turns = false;
  c.cost.sigma[5] = 0.25;
  const WorldConfig back = world_config_from_json(to_json(c));
  EXPECT_EQ(to_json(back), to_json(c));
  EXPECT_EQ(back.physics.substeps, 7);
  EXPECT_DOUBLE_EQ(back.cost.sigma[5], 0.25);
}

TEST(WorldConfig, EqualityIsFieldByFieldAsTheHashSeesIt) {
  // An expert remakes its planning world when an episode's config differs (planning_sim).
  const WorldConfig a;
  EXPECT_EQ(a, world_config_from_json(to_json(a)));
  for (auto change : std::vector<std::function<void(WorldConfig&)>>{
           [](WorldConfig& c) { c.physics.gravity.y = -4.1; }, [](WorldConfig& c) { c.dice.mass = 1.5; },
           [](WorldConfig& c) { c.cup.start_anchor.x = 3.9; }, [](WorldConfig& c) { c.cost.sigma[23] = 0.5; },
           [](WorldConfig& c) { c.randomization.shift *= 2.0; }, [](WorldConfig& c) { c.episode.max_steps = 99; }}) {
    WorldConfig b = a;
    change(b);
    EXPECT_NE(a, b);
    EXPECT_NE(world_hash(a), world_hash(b));
  }
}

TEST(WorldConfig, DeepNestingIsRefusedNotCrashed) {
  const std::string deep = "{\"physics\":" + std::string(200000, '[') + std::string(200000, ']') + "}";
  EXPECT_THAT(error_of([&] { world_config_from_json(deep, "w.json"); }),
              HasSubstr("world config w.json: JSON nested deeper than 64 levels"));
}

TEST(WorldConfig, MissingFieldIsNamed) {
  auto j = default_json();
  j["physics"].erase("substeps");
  EXPECT_THAT(error_for(j), HasSubstr("w.json: field \"physics.substeps\" is missing"));
}

TEST(WorldConfig, MistypedFieldIsNamed) {
  auto j = default_json();
  j["dice"]["mass"] = "heavy";
  EXPECT_THAT(error_for(j), HasSubstr("field \"dice.mass\" must be a number, got \"heavy\""));
  j = default_json();
  j["physics"]["substeps"] = 2.5;
  EXPECT_THAT(error_for(j), HasSubstr("field \"physics.substeps\" must be an integer, got 2.5"));
  j = default_json();
  j["cost"]["sigma"] = {1.0, 2.0};
  EXPECT_THAT(error_for(j), HasSubstr("field \"cost.sigma\" must be an array of 24 numbers"));
}

TEST(WorldConfig, NonFiniteFieldIsNamed) {
  std::string text = default_json().dump();
  const std::string key = "\"half_size\":0.2";
  const auto at = text.find(key);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, key.size(), "\"half_size\":1e999");
  const std::string msg = error_of([&] { world_config_from_json(text, "w.json"); });
  EXPECT_THAT(msg, HasSubstr("w.json: field \"half_size\" value 1e999"));
  EXPECT_THAT(msg, HasSubstr("finite"));
}

TEST(WorldConfig, OutOfRangeFieldIsNamedWithValue) {
  auto j = default_json();
  j["physics"]["substeps"] = 0;
  EXPECT_THAT(error_for(j), HasSubstr("field \"physics.substeps\" must be in [1, 1000], got 0"));
  j = default_json();
  j["cup"]["radius"] = -0.05;
  EXPECT_THAT(error_for(j), HasSubstr("field \"cup.radius\" must be in (0, 100], got -0.05"));
  j = default_json();
  j["dice"]["corner_cut"] = 0.3;
  EXPECT_THAT(error_for(j), HasSubstr("dice.corner_cut"));
}

TEST(WorldConfig, UnknownFieldIsRejected) {
  auto j = default_json();
  j["physics"]["gravty"] = -9.8;
  EXPECT_THAT(error_for(j), HasSubstr("field \"physics.gravty\" is not a world config field"));
}

TEST(WorldConfig, BrokenJsonIsRejected) {
  EXPECT_THAT(error_of([] { world_config_from_json("{\"walls\": ", "w.json"); }),
              HasSubstr("w.json: not valid JSON"));
  EXPECT_THROW(world_config_from_json("{\"walls\": ", "w.json"), ConfigError);
}

TEST(WorldConfig, ValidateRejectsBadStructs) {
  WorldConfig c;
  c.walls.left_x = 10.0;
  EXPECT_THAT(error_of([&] { validate(c); }), HasSubstr("walls.right_x"));
  c = WorldConfig{};
  c.judge.success_hold_steps = 0;
  EXPECT_THROW(validate(c), ConfigError);
}

TEST(WorldConfig, ImpossiblePhysicsIsRefusedNamingTheField) {
  auto j = default_json();
  j["physics"]["gravity"] = {0.0, -1e30};
  EXPECT_THAT(error_for(j), HasSubstr("field \"physics.gravity[1]\" must be in [-100, 100], got -1e+30"));
  j = default_json();
  j["dice"]["mass"] = 1e-300;
  EXPECT_THAT(error_for(j), HasSubstr("field \"dice.mass\" must be in [0.001, 1000], got 1e-300"));
  j = default_json();
  j["cup"]["friction"] = 1e9;
  EXPECT_THAT(error_for(j), HasSubstr("field \"cup.friction\" must be in [0, 10]"));
}

TEST(WorldConfig, DiceMustStartInsideTheWallsAndApart) {
  auto j = default_json();
  j["dice"]["start_x"] = {4.08, 4.51, 8.5};  // the shift of 0.5 pushes die 2 into the right wall
  EXPECT_THAT(error_for(j), HasSubstr("field \"dice.start_x[2]\" puts die 2 outside the walls"));
  j = default_json();
  j["dice"]["start_x"] = {4.08, 4.30, 4.93};
  EXPECT_THAT(error_for(j), HasSubstr("field \"dice.start_x[1]\" overlaps die 0"));
  j = default_json();
  j["dice"]["start_y"] = 0.9;  // inside the table
  EXPECT_THAT(error_for(j), HasSubstr("field \"dice.start_y\" puts the dice outside the walls"));
  j = default_json();
  j["dice"]["half_size"] = 100.0;
  j["dice"]["corner_cut"] = 1.0;
  EXPECT_THAT(error_for(j), HasSubstr("puts die 0 outside the walls"));
}

TEST(WorldConfig, TheCupMustStartInsideTheWallsAtEveryShiftLiftAndTilt) {
  auto j = default_json();
  j["cup"]["start_anchor"] = {4.0, 6.0};  // the lift of 0.2 reaches the ceiling
  EXPECT_THAT(error_for(j), HasSubstr("field \"cup.start_anchor\" puts the cup outside the walls"));
  j = default_json();
  j["randomization"]["shift"] = 4.0;
  EXPECT_THAT(error_for(j), HasSubstr("outside the walls"));
}

TEST(WorldConfig, WritesVersionThreeAndReadsVersionsOneAndTwo) {
  const auto j = default_json();
  EXPECT_EQ(j.at("format"), "dicestack-world");
  EXPECT_EQ(j.at("version"), 3);
  auto v2 = j;  // version 2: no embodiment, no arm: the floating cup
  v2["version"] = 2;
  v2.erase("embodiment");
  v2.erase("arm");
  EXPECT_EQ(to_json(world_config_from_json(v2.dump(), "v2.json")), to_json(WorldConfig{}));
  auto v1 = v2;  // version 1: no marker, the fields of version 2
  v1.erase("format");
  v1.erase("version");
  EXPECT_EQ(to_json(world_config_from_json(v1.dump(), "v1.json")), to_json(WorldConfig{}));
  // A version 2 file that has an arm section holds a field its version does not have.
  auto odd = j;
  odd["version"] = 2;
  EXPECT_THAT(error_for(odd), HasSubstr("is not a world config field"));
}

TEST(WorldConfig, NewerOrMalformedVersionsAreRefused) {
  auto j = default_json();
  j["version"] = 4;
  EXPECT_THAT(error_for(j), HasSubstr("w.json: format version 4 is newer than this dicestack reads (3); upgrade dicestack"));
  j["version"] = 1.5;
  EXPECT_THAT(error_for(j), HasSubstr("field \"version\" must be a positive integer, got 1.5"));
  j = default_json();
  j["format"] = "dicestack-model";
  EXPECT_THAT(error_for(j), HasSubstr("field \"format\" must be \"dicestack-world\""));
  j = default_json();
  j.erase("version");
  EXPECT_THAT(error_for(j), HasSubstr("field \"version\" is missing"));
}

TEST(WorldConfig, LongValuesAreCutInMessages) {
  auto j = default_json();
  j["dice"]["mass"] = std::string(100000, 'x');
  const std::string msg = error_for(j);
  EXPECT_THAT(msg, HasSubstr("field \"dice.mass\" must be a number"));
  EXPECT_LT(msg.size(), 300u);
}

TEST(WorldConfig, AFileThatCannotBeReadIsNamedWithTheSystemsReason) {
  namespace fs = std::filesystem;
  const fs::path path = test::scratch_path("dicestack_world_unreadable.json");
  fs::remove_all(path);
  EXPECT_EQ(error_of([&] { load_world_config(path); }), path.string() + ": cannot open for reading: No such file or directory");
  fs::create_directories(path);
  EXPECT_EQ(error_of([&] { load_world_config(path); }), path.string() + ": read failed: Is a directory");
  fs::remove(path);
  { std::ofstream(path) << to_json(WorldConfig{}); }
  fs::permissions(path, fs::perms::none);
  const auto denied = test::unprivileged([&] { return error_of([&] { load_world_config(path); }); });
  fs::remove(path);
  if (!denied) GTEST_SKIP() << "cannot drop root's privileges here";
  EXPECT_EQ(*denied, path.string() + ": cannot open for reading: Permission denied");
}

// The reference page's list is the file's: every field the writer writes, in its order, with
// the default it writes and a meaning.
TEST(WorldConfig, TheFieldListIsTheFilesFields) {
  const auto fields = world_config_fields();
  const nlohmann::json file = default_json();
  std::size_t leaves = 0;  // a section's fields, and the fields outside any section (embodiment)
  for (const auto& [key, values] : file.items())
    if (key != "format" && key != "version") leaves += values.is_object() ? values.size() : 1;
  EXPECT_EQ(fields.size(), leaves);
  for (const auto& f : fields) {
    const auto dot = f.path.find('.');
    const auto& value = dot == std::string::npos ? file.at(f.path) : file.at(f.path.substr(0, dot)).at(f.path.substr(dot + 1));
    EXPECT_EQ(f.default_value, value.dump()) << f.path;
    EXPECT_FALSE(f.meaning.empty()) << f.path;
  }
  EXPECT_EQ(fields.front().path, "walls.floor_y");
  EXPECT_EQ(fields.back().path, "arm.posture_gain");
}

TEST(WorldConfig, HashIsTheWorldsIdentityNotItsFileFormat) {
  // The value every cache name and checkpoint recorded before the format had a version.
  EXPECT_EQ(world_hash(WorldConfig{}) >> 32, 0x3f53a1beULL);
  WorldConfig c;
  c.dice.mass = 2.0;
  EXPECT_NE(world_hash(c), world_hash(WorldConfig{}));
}

}  // namespace
}  // namespace dicestack
