// DemoSplit: a set's episodes split by a named rule (episodes, rows or none), and the matrices
// of each side through any feature map.
#include <gtest/gtest.h>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/features.hpp>

#include <dicestack/test/episodes.hpp>

namespace dicestack {
namespace {

using test::episodes;

TEST(DemoSplit, EpisodeRuleGivesTheEpisodesAndTheirMatricesThroughAnyMap) {
  const auto eps = episodes(10);
  const DemoSplit split(eps, "episodes");
  ASSERT_EQ(split.train().size(), 8u);
  ASSERT_EQ(split.held_out().size(), 2u);
  EXPECT_EQ(split.held_out()[0].name, "e4");
  EXPECT_EQ(split.held_out()[1].name, "e9");
  const Split direct = split_by_episode(eps);
  EXPECT_EQ(split.matrices().train.x, direct.train.x);
  EXPECT_EQ(split.matrices().test.y, direct.test.y);
  EXPECT_EQ(split.matrices().description, direct.description);
  const FeatureMap& clock = feature_map("state+clock");
  EXPECT_EQ(split.matrices(clock).train.x, split_by_episode(eps, clock).train.x);
  EXPECT_EQ(&split.matrices(clock), &split.matrices(clock));  // made once
}

TEST(DemoSplit, RowRuleTrainsOnOnePseudoEpisodeOfTheTrainingRows) {
  const auto eps = episodes(10);
  const DemoSplit split(eps, "rows");
  const Split rows = split_by_rows(eps);
  ASSERT_EQ(split.train().size(), 1u);
  EXPECT_TRUE(split.held_out().empty());
  const Dataset pseudo = make_dataset(split.train());
  EXPECT_EQ(pseudo.x, rows.train.x);
  EXPECT_EQ(pseudo.y, rows.train.y);
  EXPECT_EQ(split.matrices().test.x, rows.test.x);
  // A map that reads the history has no meaning on shuffled rows.
  EXPECT_THROW(split.matrices(feature_map("state+clock")), ConfigError);
}

TEST(DemoSplit, NoneTrainsOnEverythingAndUnknownRulesAreRefused) {
  const auto eps = episodes(4);
  const DemoSplit split(eps, "none");
  EXPECT_EQ(split.train().size(), 4u);
  EXPECT_TRUE(split.held_out().empty());
  EXPECT_EQ(split.matrices().test.rows(), 0u);
  EXPECT_EQ(split.matrices().train.rows(), make_dataset(eps).rows());
  EXPECT_THROW(DemoSplit(eps, "halves"), ConfigError);
  EXPECT_THROW(DemoSplit({}, "episodes"), InputError);
  EXPECT_THROW(DemoSplit({}, "none"), InputError);
}

}  // namespace
}  // namespace dicestack
