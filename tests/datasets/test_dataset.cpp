#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/metrics.hpp>

namespace dicestack {
namespace {

Episode tiny(const std::string& name, std::size_t n, double offset) {
  Episode e;
  e.name = name;
  for (std::size_t t = 0; t < n; ++t) {
    State s{};
    s.fill(offset + static_cast<double>(t));
    e.states.push_back(s);
    e.actions.push_back({offset, static_cast<double>(t), -1.0});
    e.sources.push_back(StepSource::expert);
  }
  return e;
}

std::vector<Episode> episodes(std::size_t count) {
  std::vector<Episode> out;
  for (std::size_t i = 0; i < count; ++i) {
    std::string name(1, 'e');
    name += std::to_string(i);  // (GCC 12 warns falsely on "e" + to_string)
    out.push_back(tiny(name, 2 + i % 3, 10.0 * static_cast<double>(i)));
  }
  return out;
}

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

TEST(Metrics, ScaledL1ByHand) {
  Matrix y(3, 2), yhat(3, 2);
  y << 1, 2, 3, 4, 5, 6;
  yhat << 1, 3, 1, 4, 5, 2;
  const std::vector<double> sigma{2.0, 4.0};
  // Row errors: 0 + 1/4, 2/2 + 0, 0 + 4/4  -> (0.25 + 1 + 1) / 3
  EXPECT_DOUBLE_EQ(scaled_l1_error(y, yhat, sigma), 2.25 / 3.0);
  EXPECT_THROW(scaled_l1_error(y, Matrix(2, 2), sigma), InputError);
  EXPECT_THROW(scaled_l1_error(y, yhat, std::vector<double>{1.0, 0.0}), InputError);
  const auto cs = column_sigma(y);
  EXPECT_DOUBLE_EQ(cs[0], std::sqrt(8.0 / 3.0));
}

}  // namespace
}  // namespace dicestack
