#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include <dicestack/test/episodes.hpp>

namespace dicestack {
namespace {

using test::episodes;

TEST(Dataset, StacksEpisodesWithBoundaries) {
  const auto eps = episodes(3);
  const Dataset d = make_dataset(eps);
  EXPECT_EQ(d.rows(), 2u + 3u + 4u);
  EXPECT_EQ(d.x.cols(), 24);
  EXPECT_EQ(d.y.cols(), 3);
  EXPECT_EQ(d.episode_begin, (std::vector<std::size_t>{0, 2, 5}));
  EXPECT_EQ(d.x(5, 0), 20.0);
  EXPECT_EQ(d.y(6, 1), 1.0);
}

TEST(Dataset, EpisodeSplitPutsEveryFifthEpisodeInTest) {
  const auto eps = episodes(10);
  const Split s = split_by_episode(eps);
  EXPECT_EQ(s.test.episode_names, (std::vector<std::string>{"e4", "e9"}));
  EXPECT_EQ(s.train.episodes(), 8u);
  EXPECT_THAT(s.description, ::testing::HasSubstr("i % 5 == 4"));
  EXPECT_THROW(split_by_episode({}), InputError);
}

TEST(Dataset, NumpyPermutationMatchesNumpy) {
  // numpy.random.RandomState(42).permutation(10)
  EXPECT_EQ(numpy_legacy_permutation(10, 42), (std::vector<std::size_t>{8, 1, 5, 0, 7, 2, 9, 4, 3, 6}));
}

TEST(Dataset, RowSplitTakesAQuarterOfRowsDeterministically) {
  const auto eps = episodes(10);  // 29 rows
  const Split a = split_by_rows(eps), b = split_by_rows(eps);
  EXPECT_EQ(a.test.rows(), 8u);  // ceil(0.25 * 29)
  EXPECT_EQ(a.train.rows(), 21u);
  EXPECT_EQ(a.test.x, b.test.x);
  EXPECT_NE(split_by_rows(eps, 0.25, 7).test.x, a.test.x);
}

}  // namespace
}  // namespace dicestack
