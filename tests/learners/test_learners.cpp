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

TEST(Learners, AProgressLineNamesTheIterationWindowPhaseAndCount) {
  EXPECT_EQ(progress_text("dart gbt", {"demonstrations", 1, 1, 0, 0, 3, 20, 0.1}), "dart gbt: iteration 1/1, demonstrations 3/20");
  EXPECT_EQ(progress_text("dad knn", {"corrections", 2, 6, 1, 3, 4, 9, 0.2}), "dad knn: iteration 2/6, window 1/3, corrections 4/9");
  // Before the iterations (the tracker preparing its paths) there is no iteration to name.
  EXPECT_EQ(progress_text("dart gbt", {"tracker: refining path 1 of 4", 0, 0, 0, 0, 5, 60, 0.0}),
            "dart gbt: tracker: refining path 1 of 4 5/60");
  EXPECT_EQ(progress_text("bc knn", {"fit", 1, 1, 0, 0, 0, 0, 0.5}), "bc knn: iteration 1/1, fit");
}

TEST(Learners, TheTimeLeftCountsFromTheFirstFractionAboveZero) {
  // 0.45 of the job in the 100 s since it stood at 0.1: 0.45 left takes 100 s more, whatever
  // came before at 0 % (counted from the start, 300 s in, it would say 245 s).
  EXPECT_DOUBLE_EQ(time_left(100.0, 0.55, 0.1), 100.0);
  EXPECT_LT(time_left(100.0, 0.105, 0.1), 0.0);  // too little progress to tell
  EXPECT_DOUBLE_EQ(time_left(50.0, 1.0, 0.2), 0.0);
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
