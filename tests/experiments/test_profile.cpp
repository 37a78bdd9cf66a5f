// The leaderboard's profiles: quick and paper are data (rollouts, learners, rows left out,
// options per row spec), and other names are refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/profile.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

TEST(Profile, QuickAndPaperAreDataAndOtherNamesAreRefused) {
  EXPECT_EQ(leaderboard_profile_names(), (std::vector<std::string>{"quick", "paper"}));
  const Profile& quick = leaderboard_profile("quick");
  const Profile& paper = leaderboard_profile("paper");
  EXPECT_EQ(quick.rollouts, 20);
  EXPECT_EQ(paper.rollouts, 100);
  EXPECT_FALSE(quick.every_feature_map);
  EXPECT_TRUE(paper.every_feature_map);
  // Both profiles learn from the recordings alone (the tracker); the quick one with gbt only.
  const std::vector<std::string> learners{"bc", "dagger", "dart", "dart:expert=tracker"};
  EXPECT_EQ(quick.learners, learners);
  EXPECT_EQ(paper.learners, learners);
  EXPECT_EQ(quick.left_out.front(), (std::pair<std::string, std::string>{"dart", "rbf_svr"}));
  for (const char* r : {"knn", "linear_svr", "mlp", "random_forest"})
    EXPECT_NE(std::find(quick.left_out.begin(), quick.left_out.end(), std::pair<std::string, std::string>{"dart:expert=tracker", r}),
              quick.left_out.end());
  EXPECT_TRUE(paper.left_out.empty());
  EXPECT_EQ(quick.learner_options.at("dagger"), (std::vector<std::string>{"iterations=2", "rollouts=10"}));
  // A row spec's own defaults: the quick profile's tracker row follows the human recordings
  // whatever --demos names; the paper profile's tracker rows keep a kernel SVR's fit in bounds;
  // neither refines its path (the main job's minutes, a row per regressor and map).
  EXPECT_EQ(quick.learner_options.at("dart:expert=tracker"),
            (std::vector<std::string>{"tracker_demos=human", "tracker_refine=0"}));
  const std::vector<std::string> paper_tracker{"episodes=300", "tracker_shrink=0", "tracker_refine=0"};
  EXPECT_EQ(paper.learner_options.at("dart:expert=tracker"), paper_tracker);
  EXPECT_EQ(paper.options_for("dart", "dart:expert=tracker"), paper_tracker);
  EXPECT_EQ(quick.options_for("dart", "dart:expert=tracker"),
            (std::vector<std::string>{"tracker_demos=human", "tracker_refine=0"}));
  EXPECT_TRUE(quick.options_for("dart", "dart").empty());
  EXPECT_EQ(quick.options_for("dagger", "dagger"), (std::vector<std::string>{"iterations=2", "rollouts=10"}))
      << "a spec that is the learner's name is looked up once";
  EXPECT_GT(paper.optimiser_evaluations, quick.optimiser_evaluations);
  try {
    leaderboard_profile("huge");
    FAIL() << "no exception";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("profile \"huge\" is not one of quick, paper"));
  }
}

}  // namespace
}  // namespace dicestack
