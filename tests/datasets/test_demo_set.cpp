#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "../core/helpers.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = fs::path(DICESTACK_TEST_DATA);

std::string read_error(const std::string& bad) {
  return test::error_of([&] { read_demo_set(kData / "bad" / bad); });
}

TEST(DemoSet, ReadsAValidSet) {
  const DemoSet set = read_demo_set(kData / "good");
  ASSERT_EQ(set.episodes.size(), 2u);
  EXPECT_EQ(set.episodes[0].name, "episode_0000");
  EXPECT_EQ(set.episodes[0].size(), 4u);
  EXPECT_EQ(set.episodes[1].seed, 1u);
  EXPECT_EQ(set.episodes[0].sources[1], StepSource::expert);
  EXPECT_DOUBLE_EQ(set.episodes[1].states[0][state_index::kCupX], 5.0);
  EXPECT_DOUBLE_EQ(set.episodes[0].actions[2][1], 0.1333);
  EXPECT_EQ(set.description, "tiny test set");
}

TEST(DemoSet, WriteThenReadIsExact) {
  DemoSet set = read_demo_set(kData / "good");
  set.episodes[0].states[1][5] = 0.1 + 0.2;  // not exactly representable in short decimal
  set.episodes[0].outcome.stacked = true;
  set.episodes[0].origin = "unit test";
  const fs::path dir = fs::temp_directory_path() / "dicestack_demo_roundtrip";
  fs::remove_all(dir);
  write_demo_set(set, dir);
  const DemoSet back = read_demo_set(dir);
  ASSERT_EQ(back.episodes.size(), set.episodes.size());
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    EXPECT_EQ(back.episodes[i].states, set.episodes[i].states);
    EXPECT_EQ(back.episodes[i].actions, set.episodes[i].actions);
    EXPECT_EQ(back.episodes[i].sources, set.episodes[i].sources);
  }
  EXPECT_TRUE(back.episodes[0].outcome.stacked);
  EXPECT_EQ(back.episodes[0].origin, "unit test");
  // Writing again replaces the folder whole; no temporary folders are left behind.
  set.episodes.pop_back();
  write_demo_set(set, dir);
  EXPECT_EQ(read_demo_set(dir).episodes.size(), 1u);
  for (const auto& entry : fs::directory_iterator(dir.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find(".dicestack_demo_roundtrip."), std::string::npos);
  fs::remove_all(dir);
}

TEST(DemoSet, AppendAddsEpisodesAndKeepsTheOldOnes) {
  const fs::path dir = fs::temp_directory_path() / "dicestack_demo_append";
  fs::remove_all(dir);
  const DemoSet good = read_demo_set(kData / "good");
  auto names = append_to_demo_set(dir, {good.episodes[0]}, good.world, "appended");
  EXPECT_EQ(names, std::vector<std::string>{"episode_0000"});
  names = append_to_demo_set(dir, {good.episodes[1], good.episodes[0]}, good.world, "appended");
  EXPECT_EQ(names, (std::vector<std::string>{"episode_0001", "episode_0002"}));
  const DemoSet back = read_demo_set(dir);
  EXPECT_EQ(back.episodes.size(), 3u);
  EXPECT_EQ(back.episodes[1].size(), good.episodes[1].size());
  fs::remove_all(dir);
}

TEST(DemoSet, WriterRejectsMalformedEpisodes) {
  DemoSet set = read_demo_set(kData / "good");
  set.episodes[1].actions.pop_back();
  const fs::path dir = fs::temp_directory_path() / "dicestack_demo_bad_write";
  fs::remove_all(dir);
  EXPECT_THAT(test::error_of([&] { write_demo_set(set, dir); }), HasSubstr("3 states, 2 actions"));
  EXPECT_FALSE(fs::exists(dir)) << "a failed write leaves nothing behind";
}

TEST(DemoSetBadInput, HeaderAndRows) {
  EXPECT_THAT(read_error("wrong_columns"), HasSubstr("episode_0001.csv:1: header has 28 columns, expected 29"));
  EXPECT_THAT(read_error("wrong_header_name"),
              HasSubstr("episode_0001.csv:1: column 15 is \"die1_vz\", expected \"die1_vy\""));
  EXPECT_THAT(read_error("row_columns"), HasSubstr("episode_0001.csv:3: row has 30 columns, expected 29"));
  EXPECT_THAT(read_error("truncated"), HasSubstr("episode_0001.csv:4: row has"));
  EXPECT_THAT(read_error("truncated"), HasSubstr("truncated"));
  EXPECT_THAT(read_error("t_gap"), HasSubstr("episode_0001.csv:3: column \"t\" is 5, expected 1"));
}

TEST(DemoSetBadInput, Values) {
  EXPECT_THAT(read_error("not_a_number"),
              HasSubstr("episode_0001.csv:3: column \"die2_vy\": \"1.2.3\" is not a number"));
  EXPECT_THAT(read_error("nan"), HasSubstr("episode_0001.csv:3: column \"cup_x\" is NaN; demonstrations must be finite"));
  EXPECT_THAT(read_error("inf"), HasSubstr("episode_0001.csv:3: column \"dw\" is infinite"));
  EXPECT_THAT(read_error("unknown_source"),
              HasSubstr("episode_0001.csv:3: column \"source\": \"robot\" is not one of human, expert, policy, correction"));
  EXPECT_THAT(read_error("action_out_of_range"),
              HasSubstr("episode_0001.csv:3: column \"dvx\" = 25 is outside [-20, 20]"));
  EXPECT_THAT(read_error("empty_episode"), HasSubstr("episode_0001.csv: no steps"));
}

TEST(DemoSetBadInput, MetaAndFiles) {
  EXPECT_THAT(read_error("missing_file"), HasSubstr("meta.json: lists episode_0009.csv, which does not exist"));
  EXPECT_THAT(read_error("extra_file"), HasSubstr("episode_0002.csv: not listed in meta.json"));
  EXPECT_THAT(read_error("newer_version"),
              HasSubstr("meta.json: format version 3 is newer than this dicestack reads (1); upgrade dicestack"));
  EXPECT_THAT(read_error("wrong_format"), HasSubstr("format \"robomimic\" is not dicestack-demos"));
  EXPECT_THAT(read_error("steps_mismatch"), HasSubstr("says episode_0000.csv has 7 steps; the file has 4"));
  EXPECT_THAT(read_error("no_meta"), HasSubstr("meta.json: missing; not a dicestack demonstration folder"));
  EXPECT_THAT(read_error("broken_meta"), HasSubstr("meta.json: not valid JSON"));
  EXPECT_THAT(read_error("bad_world"), HasSubstr("\"physics.substeps\""));
  EXPECT_THROW(read_demo_set(kData / "bad" / "nan"), InputError);
}

}  // namespace
}  // namespace dicestack
