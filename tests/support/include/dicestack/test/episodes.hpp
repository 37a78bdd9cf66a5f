#pragma once
// Episodes compared field by field (GoogleTest expectations): what a round trip through any
// format or transport must give back.
#include <gtest/gtest.h>

#include <dicestack/datasets/episode.hpp>

namespace dicestack::test {

inline void expect_same_episode(const Episode& x, const Episode& y) {
  SCOPED_TRACE(x.name);
  EXPECT_EQ(x.name, y.name);
  EXPECT_EQ(x.seed, y.seed);
  EXPECT_EQ(x.origin, y.origin);
  EXPECT_EQ(x.states, y.states);
  EXPECT_EQ(x.actions, y.actions);
  EXPECT_EQ(x.sources, y.sources);
  EXPECT_EQ(x.final_state, y.final_state);
  EXPECT_EQ(x.rewards, y.rewards);
  EXPECT_EQ(x.terminated, y.terminated);
  EXPECT_EQ(x.truncated, y.truncated);
  EXPECT_EQ(x.outcome.steps, y.outcome.steps);
  EXPECT_EQ(x.outcome.dice_in_cup, y.outcome.dice_in_cup);
  EXPECT_EQ(x.outcome.stacked, y.outcome.stacked);
  EXPECT_EQ(x.outcome.wall_contact, y.outcome.wall_contact);
}

}  // namespace dicestack::test
