// Recording an expert's episodes: seeded, the same on any thread count, and through the tracker
// naming it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <thread>
#include <utility>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/demos.hpp>
#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using test::human_six;

TEST(Record, ExpertEpisodesAreSeededAndThreadIndependent) {
  WorldConfig w;
  w.episode.max_steps = 80;
  const auto a = record_expert("scripted", {}, w, test::record_request(4, 3, 1)), b = record_expert("scripted", {}, w, test::record_request(4, 3, 2));
  ASSERT_EQ(a.size(), 4u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].states, b[i].states);
    EXPECT_EQ(a[i].actions, b[i].actions);
    EXPECT_EQ(a[i].sources.front(), StepSource::expert);
  }
  EXPECT_THROW(record_expert("nobody", {}, w, test::record_request(1, 0, 1)), ConfigError);
  ExpertConfig torques;  // joint torques drive an arm, and this world's cup floats
  torques.controller = ActionKind::joint_torque;
  EXPECT_THROW(record_expert("scripted", torques, w, test::record_request(1, 0, 1)), ConfigError);
}

TEST(Record, BehindAnEstimatorTheExpertsFeedbackReadsTheEstimateTheSameOnAnyThreadCount) {
  WorldConfig w;
  w.episode.max_steps = 40;
  auto request = [](int threads, ExpertFeedback feedback, const char* estimator) {
    RecordRequest r = test::record_request(2, 7, threads);
    r.perturbation.observation_noise = 0.05;  // medium
    r.feedback = feedback;
    r.estimator = estimator_config(estimator);
    return r;
  };
  const auto world = record_expert("mpc", {}, w, request(1, ExpertFeedback::world, "none"));
  const auto seen = record_expert("mpc", {}, w, request(1, ExpertFeedback::observations, "none"));
  const auto one = record_expert("mpc", {}, w, request(1, ExpertFeedback::observations, "kalman"));
  const auto two = record_expert("mpc", {}, w, request(2, ExpertFeedback::observations, "kalman"));
  ASSERT_EQ(one.size(), 2u);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states);
    EXPECT_EQ(one[i].actions, two[i].actions);
    EXPECT_EQ(one[i].states.front(), world[i].states.front());  // the states recorded are the world's
    EXPECT_NE(one[i].actions, world[i].actions);
    EXPECT_NE(one[i].actions, seen[i].actions);
  }
  // Its actions answered the estimate, which a training row (what the sensors gave) does not show.
  EXPECT_THAT(test::error_of([&] { make_dataset(one); }), ::testing::HasSubstr("recorded with its expert behind an estimator"));
  EXPECT_NO_THROW(make_dataset(seen));
  // An estimator nothing reads, or that an expert in joint torques cannot run behind, is refused.
  EXPECT_THAT(test::error_of([&] { record_expert("mpc", {}, w, request(1, ExpertFeedback::world, "kalman")); }),
              ::testing::HasSubstr("give --expert-feedback observations"));
  WorldConfig arm = w;
  arm.embodiment = Embodiment::arm;
  EXPECT_THAT(test::error_of([&] { check_record_request(ActionKind::joint_torque, arm, request(1, ExpertFeedback::observations, "kalman")); }),
              ::testing::HasSubstr("runs without an estimator"));
  // The actuation factors are drawn in joint torques too.
  RecordRequest late = test::record_request(1, 0, 1);
  late.perturbation.action_delay = 1;
  late.perturbation.action_noise = 0.1;
  EXPECT_NO_THROW(check_record_request(ActionKind::joint_torque, arm, late));
}

TEST(Record, ReportsEachFinishedEpisodeOnOneThread) {
  WorldConfig w;
  w.episode.max_steps = 40;
  RecordRequest r = test::record_request(3, 3, 1);
  std::vector<std::pair<int, int>> seen;
  r.progress = [&](int done, int total) { seen.emplace_back(done, total); };
  const auto watched = record_expert("scripted", {}, w, r);
  EXPECT_EQ(seen, (std::vector<std::pair<int, int>>{{1, 3}, {2, 3}, {3, 3}}));
  const auto unwatched = record_expert("scripted", {}, w, test::record_request(3, 3, 1));
  for (std::size_t i = 0; i < watched.size(); ++i) EXPECT_EQ(watched[i].states, unwatched[i].states);
  // On three threads: only the calling thread reports, the counts never go back or past the total,
  // and the episodes are the same.
  r = test::record_request(6, 3, 3);
  const auto caller = std::this_thread::get_id();
  std::vector<int> counts;
  bool elsewhere = false;
  r.progress = [&](int done, int total) {
    elsewhere = elsewhere || std::this_thread::get_id() != caller || total != 6;
    counts.push_back(done);
  };
  const auto three = record_expert("scripted", {}, w, r), one = record_expert("scripted", {}, w, test::record_request(6, 3, 1));
  EXPECT_FALSE(elsewhere);
  ASSERT_FALSE(counts.empty());
  EXPECT_TRUE(std::is_sorted(counts.begin(), counts.end()));
  EXPECT_LE(counts.back(), 6);
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(three[i].states, one[i].states);
}

TEST(RecordTracker, RecordingThroughItDoesNotDependOnThreadsAndNamesItsExpert) {
  TrackerConfig t;
  t.probes = 1;
  t.optimise = false;
  ExpertConfig config;
  config.recordings = make_recordings(human_six(), WorldConfig{}, t, 0, 2);
  const auto one = record_expert("tracker", config, WorldConfig{}, test::record_request(2, 4, 1));
  const auto two = record_expert("tracker", config, WorldConfig{}, test::record_request(2, 4, 2));
  ASSERT_EQ(one.size(), 2u);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states);
    EXPECT_EQ(one[i].origin, "expert tracker");
  }
}

}  // namespace
}  // namespace dicestack
