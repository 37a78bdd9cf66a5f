// Outcome counts: an evaluation's rates turned back into counts of episodes.
#include <gtest/gtest.h>

#include <dicestack/learners/evaluate.hpp>

namespace dicestack {
namespace {

TEST(OutcomeCounts, AreTheRatesTimesTheEpisodes) {
  EvalStats s;
  s.episodes = 7;
  s.stacked = wilson(3, 7);
  s.wall_contact = wilson(7, 7);
  s.realistic_success = wilson(0, 7);
  const OutcomeCounts n = outcome_counts(s);
  EXPECT_EQ(n.episodes, 7);
  EXPECT_EQ(n.stacked, 3);
  EXPECT_EQ(n.wall_contact, 7);
  EXPECT_EQ(n.realistic_success, 0);
}

}  // namespace
}  // namespace dicestack
