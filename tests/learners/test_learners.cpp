// The learner registry: behaviour cloning is fitting the regressor on the demonstrations, and
// unknown names and empty demonstrations are refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

TEST(Learners, BehaviourCloningEqualsFittingTheRegressorOnTheDemonstrations) {
  const DemoSet set = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext c;
  c.demos = set.episodes;
  c.regressor = "linear_svr";
  c.seed = 5;
  const LearnResult r = LearnerRegistry::global().create("bc")->learn(c);
  const Dataset d = make_dataset(set.episodes);
  const Model direct = Model::train(RegressorRegistry::global().create("linear_svr"), d.x, d.y, 5);
  EXPECT_EQ(r.model->predict(d.x), direct.predict(d.x));
}

TEST(Learners, UnknownNamesAndEmptyDemosAreRejected) {
  EXPECT_THAT(test::error_of([] { LearnerRegistry::global().create("dagr"); }), ::testing::HasSubstr("unknown learner \"dagr\"; registered: bc"));
  LearnContext c;
  c.regressor = "knn";
  EXPECT_THROW(LearnerRegistry::global().create("bc")->learn(c), InputError);
  c.demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good").episodes;
  c.regressor = "nope";
  EXPECT_THROW(LearnerRegistry::global().create("bc")->learn(c), ConfigError);
}

}  // namespace
}  // namespace dicestack
