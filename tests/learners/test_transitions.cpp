// Demonstration format v2's additions from every producer of episodes, and their recovery for
// v1 sets by replaying in the deterministic world.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/replay.hpp>
#include <dicestack/learners/record.hpp>
#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

TEST(Transitions, RolloutsRecordTheFinalStateRewardsAndEnd) {
  const WorldConfig w = test::short_world();
  const State goal = goal_state(w);
  for (const Episode& e : record_expert("scripted", {}, w, test::record_request(3, 4, 1))) {
    ASSERT_TRUE(e.has_transitions()) << e.name;
    ASSERT_EQ(e.rewards.size(), e.size());
    for (std::size_t t = 0; t < e.size(); ++t) {
      const State& next = t + 1 < e.size() ? e.states[t + 1] : *e.final_state;
      EXPECT_EQ(e.rewards[t], step_reward(next, static_cast<int>(t + 1), w, goal)) << t;
    }
    EXPECT_NE(e.terminated, e.truncated);
    EXPECT_EQ(e.truncated, static_cast<int>(e.size()) == w.episode.max_steps);
  }
}

TEST(Transitions, VersionOneEpisodesAreRecoveredExactlyByReplay) {
  const WorldConfig w = test::short_world();
  const auto recorded = record_expert("scripted", {}, w, test::record_request(3, 9, 1));
  std::vector<Episode> v1 = recorded;
  for (auto& e : v1) e.clear_transitions();
  EXPECT_TRUE(recover_transitions(v1, w).empty());
  for (std::size_t i = 0; i < v1.size(); ++i) {
    EXPECT_EQ(*v1[i].final_state, *recorded[i].final_state);
    EXPECT_EQ(v1[i].rewards, recorded[i].rewards);
    EXPECT_EQ(v1[i].terminated, recorded[i].terminated);
    EXPECT_EQ(v1[i].truncated, recorded[i].truncated);
  }
}

TEST(Transitions, EpisodesThatDoNotReplayAreNamedAndLeftAlone) {
  const WorldConfig w = test::short_world();
  // DART: the world executed noisy actions, the file holds the clean labels.
  auto noisy = record_expert("scripted", {}, w, test::record_request(2, 1, 1, Action{0.3, 0.3, 0.3}));
  noisy[0].name = "noisy_0";
  noisy[1].name = "noisy_1";
  for (auto& e : noisy) e.clear_transitions();
  EXPECT_EQ(recover_transitions(noisy, w), (std::vector<std::string>{"noisy_0", "noisy_1"}));
  EXPECT_FALSE(noisy[0].has_transitions());
  EXPECT_TRUE(noisy[0].rewards.empty());
  // One recorded state moved by more than the tolerance.
  auto edited = record_expert("scripted", {}, w, test::record_request(1, 2, 1));
  edited[0].clear_transitions();
  edited[0].states[5][state_index::kCupX] += 1e-6;
  EXPECT_FALSE(recover_transitions(edited[0], w));
}

}  // namespace
}  // namespace dicestack
