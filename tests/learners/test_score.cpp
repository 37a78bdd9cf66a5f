// A model's score: eq. 9 with sigma from the training labels, and no test error without test
// rows.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/metrics.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/registry.hpp>
#include <dicestack/regressors/score.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

std::vector<Episode> good_episodes() {
  return read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good").episodes;
}

TEST(Score, IsEquationNineWithSigmaFromTheTrainingLabelsAndNoTestErrorWithoutTestRows) {
  std::vector<Episode> eps = good_episodes();
  while (eps.size() < 5) {  // a fifth episode makes a test side
    const Episode copy = eps[eps.size() % 2];
    eps.push_back(copy);
  }
  const DemoSplit split(eps, "episodes");
  const Split& m = split.matrices();
  const Model model = Model::train(RegressorRegistry::global().create("linear_svr"), m.train.x, m.train.y, 1);
  const Score s = score(model, split);
  const auto sigma = column_sigma(m.train.y);
  EXPECT_EQ(s.train_error, scaled_l1_error(m.train.y, model.predict(m.train.x), sigma));
  ASSERT_TRUE(s.test_error.has_value());
  EXPECT_EQ(*s.test_error, scaled_l1_error(m.test.y, model.predict(m.test.x), sigma));
  EXPECT_EQ(s.split, m.description);

  const Score all = score(model, DemoSplit(eps, "none"));  // no test rows: none, not 0
  EXPECT_FALSE(all.test_error.has_value());
  EXPECT_THAT(all.split, HasSubstr("none"));
}

}  // namespace
}  // namespace dicestack
